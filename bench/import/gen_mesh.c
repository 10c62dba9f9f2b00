/* Writes a torus of U x V quads split into 2UV triangles as a binary
 * little-endian PLY (float x y z, list uchar int vertex_indices) and as an OBJ
 * (v / f lines), the inputs of bench/import/run_import_bench.sh.
 * Usage: iris_gen_mesh U V out.ply out.obj */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv) {
  if (argc != 5) {
    fprintf(stderr, "usage: iris_gen_mesh U V out.ply out.obj\n");
    return 2;
  }
  const long U = atol(argv[1]), V = atol(argv[2]);
  if (U < 3 || V < 3) return 2;
  const double pi = 3.14159265358979323846;
  FILE *ply = fopen(argv[3], "wb"), *obj = fopen(argv[4], "w");
  if (!ply || !obj) return 1;
  fprintf(ply,
          "ply\nformat binary_little_endian 1.0\ncomment iris bench torus\nelement vertex %ld\n"
          "property float x\nproperty float y\nproperty float z\nelement face %ld\n"
          "property list uchar int vertex_indices\nend_header\n",
          U * V, 2 * U * V);
  fprintf(obj, "# iris bench torus %ld x %ld\n", U, V);
  for (long i = 0; i < U; i++)
    for (long j = 0; j < V; j++) {
      double a = 2 * pi * i / U, b = 2 * pi * j / V;
      float p[3] = {(float)((1 + 0.3 * cos(b)) * cos(a)), (float)(0.3 * sin(b)),
                    (float)((1 + 0.3 * cos(b)) * sin(a))};
      fwrite(p, sizeof p, 1, ply);
      fprintf(obj, "v %.6f %.6f %.6f\n", p[0], p[1], p[2]);
    }
  for (long i = 0; i < U; i++)
    for (long j = 0; j < V; j++) {
      int32_t a = (int32_t)(i * V + j), b = (int32_t)(((i + 1) % U) * V + j),
              c = (int32_t)(((i + 1) % U) * V + (j + 1) % V), d = (int32_t)(i * V + (j + 1) % V);
      int32_t t[2][3] = {{a, d, c}, {a, c, b}};
      for (int k = 0; k < 2; k++) {
        unsigned char n = 3;
        fwrite(&n, 1, 1, ply);
        fwrite(t[k], sizeof t[k], 1, ply);
        fprintf(obj, "f %d %d %d\n", t[k][0] + 1, t[k][1] + 1, t[k][2] + 1);
      }
    }
  return fclose(ply) || fclose(obj);
}
