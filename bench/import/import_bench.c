/* Times iris's OBJ/PLY import of each file given on the command line (the same
 * call `iris import` makes) and prints counts, seconds, triangles per second
 * and the process's peak resident memory. Usage:
 *   iris_import_bench [--repeat N] [--weld] [--no-normals] [--openmesh-normals] FILE... */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "core/log.h"
#include "importers/import.h"
#include "importers/meshproc.h"

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* What iris_import_file does for .obj/.ply: the importer, then validation.
 * (Called directly: import.c references the importers weakly, which does not
 * pull them out of the static library by itself.) */
static iris_status import_file(const char *path, const iris_import_options *opts,
                               iris_scene **out, iris_error *err) {
  const size_t n = strlen(path);
  iris_status st;
  if (n > 4 && !strcmp(path + n - 4, ".obj")) st = iris_import_obj(path, opts, out, err);
  else if (n > 4 && !strcmp(path + n - 4, ".ply")) st = iris_import_ply(path, opts, out, err);
  else return iris_import_file(path, opts, out, err);
  if (st != IRIS_OK) return st;
  st = iris_scene_validate(*out, path, err);
  if (st != IRIS_OK) iris_scene_destroy(*out), *out = NULL;
  return st;
}

int main(int argc, char **argv) {
  iris_import_options opts = iris_import_options_default();
  int repeat = 1;
  bool om = false;
  int status = 0;
  iris_log_set_level(IRIS_LOG_WARN);
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--repeat") && i + 1 < argc) { repeat = atoi(argv[++i]); continue; }
    if (!strcmp(argv[i], "--weld")) { opts.weld = true; continue; }
    if (!strcmp(argv[i], "--no-normals")) { opts.compute_normals = false; continue; }
    if (!strcmp(argv[i], "--openmesh-normals")) { om = true; continue; }
    double best = 1e30;
    iris_scene *scene = NULL;
    for (int r = 0; r < repeat; r++) {
      iris_error err;
      iris_error_clear(&err);
      iris_scene_destroy(scene);
      scene = NULL;
      double t0 = now();
      iris_status st = import_file(argv[i], &opts, &scene, &err);
      double t = now() - t0;
      if (st != IRIS_OK) {
        char buf[1400];
        iris_error_format(&err, buf, sizeof buf);
        printf("%s\tREJECTED\t%s\n", argv[i], buf);
        status = 2;
        break;
      }
      if (t < best) best = t;
    }
    if (!scene) continue;
    uint64_t verts = 0, tris = 0;
    int with_normals = 0;
    for (size_t m = 0; m < scene->mesh_count; m++) {
      verts += scene->meshes[m].vertex_count;
      tris += scene->meshes[m].triangle_count;
      with_normals += scene->meshes[m].normals != NULL;
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("%s\tmeshes %zu\tmaterials %zu\ttextures %zu\tvertices %llu\ttriangles %llu\tnormals %d\t"
           "%.4f s\t%.2f Mtri/s\tpeak RSS %.1f MB (%.0f B/tri)\n",
           argv[i], scene->mesh_count, scene->material_count, scene->texture_count,
           (unsigned long long)verts, (unsigned long long)tris, with_normals, best,
           tris / best * 1e-6, ru.ru_maxrss / 1024.0, ru.ru_maxrss * 1024.0 / (double)(tris ? tris : 1));
    if (om) {
      for (size_t m = 0; m < scene->mesh_count; m++) {
        iris_mesh *mesh = &scene->meshes[m];
        float *n = malloc(3 * (size_t)mesh->vertex_count * sizeof(float) + 1);
        double t0 = now();
        bool ok = iris_normals_openmesh(mesh->positions, mesh->vertex_count, mesh->indices,
                                        mesh->triangle_count, n);
        double t1 = now();
        float *a = calloc(3 * (size_t)mesh->vertex_count + 1, sizeof(float));
        iris_normals_accumulate(mesh->positions, mesh->indices, mesh->triangle_count, a);
        iris_normals_normalize(a, mesh->vertex_count);
        double t2 = now();
        printf("  mesh %zu: OpenMesh normals %s %.4f s, plain arrays %.4f s\n", m,
               ok ? "ok" : "REFUSED (non-manifold)", t1 - t0, t2 - t1);
        free(n);
        free(a);
      }
    }
    iris_scene_destroy(scene);
  }
  return status;
}
