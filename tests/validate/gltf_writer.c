/* tests/validate/gltf_writer.h */
#include "gltf_writer.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int gw_material(gltf_writer *w, const char *json) {
  w->materials[w->material_count] = json;
  return w->material_count++;
}

int gw_mesh_begin(gltf_writer *w, int material) {
  gw_mesh *m = &w->meshes[w->mesh_count];
  memset(m, 0, sizeof *m);
  m->material = material;
  return w->mesh_count++;
}

static uint32_t add_vertex(gw_mesh *m, const float p[3], const float n[3]) {
  if (m->nv == m->cap_v) {
    m->cap_v = m->cap_v ? 2 * m->cap_v : 256;
    m->pos = realloc(m->pos, 3 * sizeof(float) * m->cap_v);
    m->nrm = realloc(m->nrm, 3 * sizeof(float) * m->cap_v);
  }
  memcpy(m->pos + 3 * m->nv, p, 3 * sizeof(float));
  memcpy(m->nrm + 3 * m->nv, n, 3 * sizeof(float));
  return m->nv++;
}

static void add_tri(gw_mesh *m, uint32_t a, uint32_t b, uint32_t c) {
  if (m->nt == m->cap_t) {
    m->cap_t = m->cap_t ? 2 * m->cap_t : 256;
    m->idx = realloc(m->idx, 3 * sizeof(uint32_t) * m->cap_t);
  }
  m->idx[3 * m->nt] = a;
  m->idx[3 * m->nt + 1] = b;
  m->idx[3 * m->nt + 2] = c;
  m->nt++;
}

void gw_quad(gltf_writer *w, int mesh, const float p0[3], const float u[3], const float v[3], int n) {
  gw_mesh *m = &w->meshes[mesh];
  float nr[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  float l = sqrtf(nr[0] * nr[0] + nr[1] * nr[1] + nr[2] * nr[2]);
  for (int k = 0; k < 3; k++) nr[k] /= l;
  uint32_t base = m->nv;
  for (int j = 0; j <= n; j++)
    for (int i = 0; i <= n; i++) {
      float p[3];
      for (int k = 0; k < 3; k++) p[k] = p0[k] + u[k] * (float)i / (float)n + v[k] * (float)j / (float)n;
      add_vertex(m, p, nr);
    }
  for (int j = 0; j < n; j++)
    for (int i = 0; i < n; i++) {
      uint32_t a = base + (uint32_t)(j * (n + 1) + i), b = a + 1, c = a + (uint32_t)(n + 1) + 1,
               d = a + (uint32_t)(n + 1);
      add_tri(m, a, b, c);
      add_tri(m, a, c, d);
    }
}

void gw_box(gltf_writer *w, int mesh, const float lo[3], const float hi[3], bool inward, int n) {
  for (int axis = 0; axis < 3; axis++)
    for (int side = 0; side < 2; side++) {
      int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      float p0[3], u[3] = {0, 0, 0}, v[3] = {0, 0, 0};
      p0[axis] = side ? hi[axis] : lo[axis];
      p0[a1] = lo[a1];
      p0[a2] = lo[a2];
      u[a1] = hi[a1] - lo[a1];
      v[a2] = hi[a2] - lo[a2];
      /* u x v points along +axis; outward on the hi side, so swap for lo. */
      bool flip = (side == 0) != inward;
      if (flip) {
        p0[a1] = hi[a1];
        u[a1] = -u[a1];
      }
      gw_quad(w, mesh, p0, u, v, n);
    }
}

void gw_sphere(gltf_writer *w, int mesh, const float c[3], float r, int rings, int segments) {
  gw_mesh *m = &w->meshes[mesh];
  uint32_t base = m->nv;
  for (int j = 0; j <= rings; j++) {
    double th = 3.14159265358979323846 * j / rings;
    for (int i = 0; i <= segments; i++) {
      double ph = 2.0 * 3.14159265358979323846 * i / segments;
      float n[3] = {(float)(sin(th) * cos(ph)), (float)cos(th), (float)(-sin(th) * sin(ph))};
      float p[3] = {c[0] + r * n[0], c[1] + r * n[1], c[2] + r * n[2]};
      add_vertex(m, p, n);
    }
  }
  for (int j = 0; j < rings; j++)
    for (int i = 0; i < segments; i++) {
      uint32_t a = base + (uint32_t)(j * (segments + 1) + i), b = a + 1,
               d = a + (uint32_t)(segments + 1), e = d + 1;
      if (j > 0) add_tri(m, a, d, b);
      if (j < rings - 1) add_tri(m, b, d, e);
    }
}

void gw_camera(gltf_writer *w, const float pos[3], const float q[4], float yfov, float aspect) {
  w->has_camera = true;
  memcpy(w->cam_pos, pos, sizeof w->cam_pos);
  memcpy(w->cam_rot, q, sizeof w->cam_rot);
  w->cam_yfov = yfov;
  w->cam_aspect = aspect;
}

int gw_write(gltf_writer *w, const char *path) {
  char bin[1024];
  snprintf(bin, sizeof bin, "%.*s.bin", (int)(strlen(path) - 5), path);
  const char *bin_name = strrchr(bin, '/') ? strrchr(bin, '/') + 1 : bin;
  FILE *fb = fopen(bin, "wb"), *fj = fopen(path, "w");
  if (!fb || !fj) return -1;
  size_t offset = 0;
  fprintf(fj, "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_materials_specular\","
              "\"KHR_materials_transmission\",\"KHR_materials_emissive_strength\",\"KHR_materials_ior\"],\n");
  /* bufferViews + accessors: 3 per mesh (positions, normals, indices) */
  fputs("\"bufferViews\":[", fj);
  for (int i = 0; i < w->mesh_count; i++) {
    gw_mesh *m = &w->meshes[i];
    size_t sv = 12 * (size_t)m->nv, si = 12 * (size_t)m->nt;
    fprintf(fj, "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},", i ? "," : "", offset, sv);
    fwrite(m->pos, 1, sv, fb);
    offset += sv;
    fprintf(fj, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},", offset, sv);
    fwrite(m->nrm, 1, sv, fb);
    offset += sv;
    fprintf(fj, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", offset, si);
    fwrite(m->idx, 1, si, fb);
    offset += si;
  }
  fprintf(fj, "],\n\"buffers\":[{\"uri\":\"%s\",\"byteLength\":%zu}],\n\"accessors\":[", bin_name, offset);
  for (int i = 0; i < w->mesh_count; i++) {
    gw_mesh *m = &w->meshes[i];
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t v = 0; v < m->nv; v++)
      for (int k = 0; k < 3; k++) {
        lo[k] = fminf(lo[k], m->pos[3 * v + k]);
        hi[k] = fmaxf(hi[k], m->pos[3 * v + k]);
      }
    fprintf(fj, "%s{\"bufferView\":%d,\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\","
                "\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]},",
            i ? "," : "", 3 * i, m->nv, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    fprintf(fj, "{\"bufferView\":%d,\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\"},", 3 * i + 1, m->nv);
    fprintf(fj, "{\"bufferView\":%d,\"componentType\":5125,\"count\":%u,\"type\":\"SCALAR\"}", 3 * i + 2,
            3 * m->nt);
  }
  fputs("],\n\"materials\":[", fj);
  for (int i = 0; i < w->material_count; i++) fprintf(fj, "%s%s\n", i ? "," : "", w->materials[i]);
  fputs("],\n\"meshes\":[", fj);
  for (int i = 0; i < w->mesh_count; i++)
    fprintf(fj, "%s{\"primitives\":[{\"attributes\":{\"POSITION\":%d,\"NORMAL\":%d},\"indices\":%d,"
                "\"material\":%d}]}",
            i ? "," : "", 3 * i, 3 * i + 1, 3 * i + 2, w->meshes[i].material);
  fputs("],\n\"nodes\":[", fj);
  for (int i = 0; i < w->mesh_count; i++) fprintf(fj, "%s{\"mesh\":%d}", i ? "," : "", i);
  if (w->has_camera)
    fprintf(fj, ",{\"camera\":0,\"translation\":[%.9g,%.9g,%.9g],\"rotation\":[%.9g,%.9g,%.9g,%.9g]}",
            w->cam_pos[0], w->cam_pos[1], w->cam_pos[2], w->cam_rot[0], w->cam_rot[1], w->cam_rot[2],
            w->cam_rot[3]);
  fputs("],\n", fj);
  if (w->has_camera)
    fprintf(fj, "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":%.9g,"
                "\"aspectRatio\":%.9g,\"znear\":0.01}}],\n",
            w->cam_yfov, w->cam_aspect);
  fputs("\"scenes\":[{\"nodes\":[", fj);
  int nodes = w->mesh_count + (w->has_camera ? 1 : 0);
  for (int i = 0; i < nodes; i++) fprintf(fj, "%s%d", i ? "," : "", i);
  fputs("]}],\"scene\":0}\n", fj);
  for (int i = 0; i < w->mesh_count; i++) {
    free(w->meshes[i].pos);
    free(w->meshes[i].nrm);
    free(w->meshes[i].idx);
  }
  w->mesh_count = 0;
  int bad = ferror(fb) || ferror(fj);
  fclose(fb);
  fclose(fj);
  return bad ? -1 : 0;
}
