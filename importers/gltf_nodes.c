/* glTF 2.0 import: the node hierarchy and what it places. Validates cameras,
 * KHR_lights_punctual lights and the node graph (one parent each, no cycles),
 * then walks the default scene placing mesh instances (EXT_mesh_gpu_instancing
 * included), lights and perspective cameras with their world transforms.
 * Accessors and primitives: gltf_convert.c. Mapping: docs/import-gltf.md. */
#include "importers/gltf_private.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/log.h"

/* Instances (nodes x primitives) are not bounded by the file size; cap them. */
#define MAX_INSTANCES ((size_t)1 << 22)

static dmat4 dmat4_identity(void) {
  dmat4 r;
  memset(&r, 0, sizeof r);
  for (int i = 0; i < 4; i++) r.m[i][i] = 1.0;
  return r;
}

static dmat4 dmat4_mul(const dmat4 *a, const dmat4 *b) {
  dmat4 r;
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) {
      double s = 0.0;
      for (int k = 0; k < 4; k++) s += a->m[i][k] * b->m[k][j];
      r.m[i][j] = s;
    }
  return r;
}

static iris_mat4 dmat4_to_float(const dmat4 *a) {
  iris_mat4 r;
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) r.m[i][j] = (float)a->m[i][j];
  return r;
}

static bool all_finite(const double *v, size_t n) {
  for (size_t i = 0; i < n; i++)
    if (!isfinite(v[i])) return false;
  return true;
}

iris_status gltf_validate_cameras_lights(gltf_ctx *c) {
  const iris_gltf_doc *d = c->doc;
  char el[64];
  iris_status st;
  for (size_t i = 0; i < d->camera_count; i++) {
    const iris_gltf_camera *cam = &d->cameras[i];
    ELEMENT(el, "camera %zu", i);
    if (strcmp(cam->type, "perspective") == 0) {
      if (!isfinite(cam->yfov) || cam->yfov <= 0.0 || cam->yfov >= IRIS_PI)
        return gltf_fail(c, IRIS_ERR_INVALID, el, "yfov %g is not in (0, pi)", cam->yfov);
      if (!isfinite(cam->aspect) || cam->aspect < 0.0)
        return gltf_fail(c, IRIS_ERR_INVALID, el, "aspectRatio %g is not positive", cam->aspect);
    } else if (strcmp(cam->type, "orthographic") != 0) {
      return gltf_fail(c, IRIS_ERR_INVALID, el, "invalid type '%s'", cam->type);
    }
  }
  for (size_t i = 0; i < d->light_count; i++) {
    const iris_gltf_light *l = &d->lights[i];
    ELEMENT(el, "KHR_lights_punctual light %zu", i);
    if (strcmp(l->type, "point") && strcmp(l->type, "spot") && strcmp(l->type, "directional"))
      return gltf_fail(c, IRIS_ERR_INVALID, el, "invalid type '%s'", l->type);
    if (l->color_len != 0 && l->color_len != 3)
      return gltf_fail(c, IRIS_ERR_INVALID, el, "color has %zu values (3 expected)", l->color_len);
    for (size_t k = 0; k < l->color_len; k++)
      if ((st = gltf_check_range(c, el, "color component", l->color[k], 0, 1))) return st;
    if ((st = gltf_check_range(c, el, "intensity", l->intensity, 0, HUGE_VAL)) ||
        (st = gltf_check_range(c, el, "range", l->range, 0, HUGE_VAL)))
      return st;
    if (strcmp(l->type, "spot") == 0) {
      if ((st = gltf_check_range(c, el, "spot.outerConeAngle", l->outer_cone, 0, IRIS_PI / 2 + 1e-6)) ||
          (st = gltf_check_range(c, el, "spot.innerConeAngle", l->inner_cone, 0, l->outer_cone)))
        return st;
      if (l->inner_cone >= l->outer_cone)
        return gltf_fail(c, IRIS_ERR_INVALID, el, "innerConeAngle must be less than outerConeAngle");
    }
  }
  return IRIS_OK;
}

/* Local matrix of a node: `matrix` (column-major) or T * R * S. */
static iris_status node_local(gltf_ctx *c, size_t ni, dmat4 *out) {
  const iris_gltf_node *n = &c->doc->nodes[ni];
  char el[32];
  ELEMENT(el, "node %zu", ni);
  if ((n->matrix_len != 0 && n->matrix_len != 16) || (n->translation_len != 0 && n->translation_len != 3) ||
      (n->rotation_len != 0 && n->rotation_len != 4) || (n->scale_len != 0 && n->scale_len != 3))
    return gltf_fail(c, IRIS_ERR_INVALID, el, "matrix/translation/rotation/scale has the wrong length");
  if (!all_finite(n->matrix, n->matrix_len) || !all_finite(n->translation, n->translation_len) ||
      !all_finite(n->rotation, n->rotation_len) || !all_finite(n->scale, n->scale_len))
    return gltf_fail(c, IRIS_ERR_INVALID, el, "non-finite transform value");
  *out = dmat4_identity();
  if (n->matrix_len == 16) {
    if (n->translation_len || n->rotation_len || n->scale_len) c->warned_matrix_trs = true;
    for (int r = 0; r < 4; r++)
      for (int col = 0; col < 4; col++) out->m[r][col] = n->matrix[col * 4 + r];
    return IRIS_OK;
  }
  double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
  if (n->translation_len) memcpy(t, n->translation, sizeof t);
  if (n->rotation_len) memcpy(q, n->rotation, sizeof q);
  if (n->scale_len) memcpy(s, n->scale, sizeof s);
  double len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(len > 1e-12) || !isfinite(len))
    return gltf_fail(c, IRIS_ERR_INVALID, el, "rotation quaternion has zero length");
  for (int k = 0; k < 4; k++) q[k] /= len;
  double x = q[0], y = q[1], z = q[2], w = q[3];
  double R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                    {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                    {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
  for (int r = 0; r < 3; r++) {
    for (int col = 0; col < 3; col++) out->m[r][col] = R[r][col] * s[col];
    out->m[r][3] = t[r];
  }
  return IRIS_OK;
}

/* Parents, single-parent rule and cycles (nodes unreachable from any root). */
iris_status gltf_validate_node_graph(gltf_ctx *c) {
  const iris_gltf_doc *d = c->doc;
  size_t nn = d->node_count;
  char el[32];
  c->parent = malloc((nn ? nn : 1) * sizeof *c->parent);
  int *stack = malloc((nn ? nn : 1) * sizeof *stack);
  bool *seen = calloc(nn ? nn : 1, sizeof *seen);
  if (!c->parent || !stack || !seen) {
    free(stack), free(seen);
    return gltf_fail(c, IRIS_ERR_NOMEM, NULL, "out of memory");
  }
  iris_status st = IRIS_OK;
  for (size_t i = 0; i < nn; i++) c->parent[i] = -1;
  for (size_t i = 0; i < nn && !st; i++) {
    const iris_gltf_node *n = &d->nodes[i];
    ELEMENT(el, "node %zu", i);
    if (n->mesh != -1 && (n->mesh < 0 || (size_t)n->mesh >= d->mesh_count))
      st = gltf_fail(c, IRIS_ERR_INVALID, el, "mesh %d does not exist (%zu meshes)", n->mesh, d->mesh_count);
    else if (n->camera != -1 && (n->camera < 0 || (size_t)n->camera >= d->camera_count))
      st = gltf_fail(c, IRIS_ERR_INVALID, el, "camera %d does not exist (%zu cameras)", n->camera, d->camera_count);
    else if (n->light != -1 && (n->light < 0 || (size_t)n->light >= d->light_count))
      st = gltf_fail(c, IRIS_ERR_INVALID, el, "KHR_lights_punctual light %d does not exist (%zu lights)",
                n->light, d->light_count);
    for (size_t k = 0; k < n->child_count && !st; k++) {
      int ch = n->children[k];
      if (ch < 0 || (size_t)ch >= nn)
        st = gltf_fail(c, IRIS_ERR_INVALID, el, "child %d does not exist (%zu nodes)", ch, nn);
      else if ((size_t)ch == i)
        st = gltf_fail(c, IRIS_ERR_INVALID, el, "is its own child");
      else if (c->parent[ch] >= 0)
        st = gltf_fail(c, IRIS_ERR_INVALID, el, "child %d already has parent node %d (a node may have one parent)",
                  ch, c->parent[ch]);
      else
        c->parent[ch] = (int)i;
    }
    if (n->skin >= 0) c->warned_skin = true;
    if (n->has_weights) c->warned_morph = true;
  }
  /* With one parent each, the nodes not reachable from a root lie on or below a cycle. */
  size_t top = 0;
  for (size_t i = 0; i < nn && !st; i++)
    if (c->parent[i] < 0) stack[top++] = (int)i;
  while (top > 0 && !st) {
    int ni = stack[--top];
    seen[ni] = true;
    for (size_t k = 0; k < d->nodes[ni].child_count; k++) stack[top++] = d->nodes[ni].children[k];
  }
  for (size_t i = 0; i < nn && !st; i++)
    if (!seen[i]) {
      ELEMENT(el, "node %zu", i);
      st = gltf_fail(c, IRIS_ERR_INVALID, el, "is part of a cycle in the node hierarchy");
    }
  free(stack);
  free(seen);
  return st;
}

typedef struct camera_hit {
  int node, camera;
} camera_hit;

static iris_status add_instance_prims(gltf_ctx *c, int mesh, const dmat4 *world) {
  const iris_gltf_mesh *gm = &c->doc->meshes[mesh];
  iris_status st;
  for (size_t pi = 0; pi < gm->primitive_count; pi++) {
    converted_prim *cp = &c->prims[mesh][pi];
    if (!cp->valid) continue;
    if (cp->scene_mesh < 0) {
      if ((st = gltf_resolve_material(c, cp->gltf_material, &cp->mesh.material))) return st;
      int32_t id = iris_scene_add_mesh(c->scene, &cp->mesh);
      if (id < 0) return gltf_fail(c, IRIS_ERR_NOMEM, NULL, "out of memory");
      memset(&cp->mesh, 0, sizeof cp->mesh); /* the scene owns the arrays now */
      cp->scene_mesh = id;
    }
    if (c->scene->instance_count >= MAX_INSTANCES)
      return gltf_fail(c, IRIS_ERR_NOMEM, NULL, "more than %zu mesh instances", MAX_INSTANCES);
    iris_instance inst;
    inst.mesh = (uint32_t)cp->scene_mesh;
    inst.transform = dmat4_to_float(world);
    if (iris_scene_add_instance(c->scene, &inst) < 0) return gltf_fail(c, IRIS_ERR_NOMEM, NULL, "out of memory");
  }
  return IRIS_OK;
}

/* One EXT_mesh_gpu_instancing attribute: accessor `ai` (-1: absent, then
 * `fallback` for every instance) read as `count` x ncomp floats into out.
 * Float, or for ROTATION normalized signed byte/short (the extension's
 * types); every value finite. */
static iris_status read_instance_attribute(gltf_ctx *c, size_t node, const char *name, int ai, int ncomp,
                                           bool rotation, size_t count, const float *fallback, float *out) {
  char el[64];
  ELEMENT(el, "node %zu EXT_mesh_gpu_instancing %s", node, name);
  if (ai == -1) {
    for (size_t i = 0; i < count; i++) memcpy(out + i * (size_t)ncomp, fallback, (size_t)ncomp * sizeof(float));
    return IRIS_OK;
  }
  const iris_gltf_doc *d = c->doc;
  if (ai < 0 || (size_t)ai >= d->accessor_count)
    return gltf_fail(c, IRIS_ERR_INVALID, el, "accessor %d does not exist (%zu accessors)", ai, d->accessor_count);
  const iris_gltf_accessor *a = &d->accessors[ai];
  if (a->type != ncomp)
    return gltf_fail(c, IRIS_ERR_INVALID, el, "accessor %d must be VEC%d", ai, ncomp);
  bool ok = a->component_type == 5126 ||
            (rotation && a->normalized && (a->component_type == 5120 || a->component_type == 5122));
  if (!ok)
    return gltf_fail(c, IRIS_ERR_INVALID, el, "accessor %d has componentType %d (%s)", ai, a->component_type,
                     rotation ? "float or normalized byte/short" : "float");
  if (a->count != count)
    return gltf_fail(c, IRIS_ERR_INVALID, el, "accessor %d has %zu elements, the other attributes %zu", ai,
                     a->count, count);
  gltf_read_floats(d, a, ncomp, out);
  for (size_t i = 0; i < count * (size_t)ncomp; i++)
    if (!isfinite(out[i]))
      return gltf_fail(c, IRIS_ERR_INVALID, el, "instance %zu has a non-finite value", i / (size_t)ncomp);
  return IRIS_OK;
}

/* The node's mesh placed once per EXT_mesh_gpu_instancing instance:
 * world = node world x T(translation) R(rotation) S(scale). */
static iris_status add_gpu_instances(gltf_ctx *c, size_t node, const dmat4 *world) {
  const iris_gltf_node *n = &c->doc->nodes[node];
  char el[64];
  ELEMENT(el, "node %zu EXT_mesh_gpu_instancing", node);
  if (n->gpu_instancing_bad)
    return gltf_fail(c, IRIS_ERR_INVALID, el, "is not an object with an \"attributes\" object");
  int refs[3] = {n->inst_translation, n->inst_rotation, n->inst_scale};
  size_t count = 0;
  bool any = false;
  for (int k = 0; k < 3; k++) {
    if (refs[k] == -1) continue;
    if (refs[k] < 0 || (size_t)refs[k] >= c->doc->accessor_count)
      return gltf_fail(c, IRIS_ERR_INVALID, el, "%s accessor %d does not exist (%zu accessors)",
                       k == 0 ? "TRANSLATION" : k == 1 ? "ROTATION" : "SCALE", refs[k], c->doc->accessor_count);
    if (!any) count = c->doc->accessors[refs[k]].count, any = true;
  }
  if (!any) return gltf_fail(c, IRIS_ERR_INVALID, el, "has none of TRANSLATION, ROTATION, SCALE");
  if (count == 0) return gltf_fail(c, IRIS_ERR_INVALID, el, "has no instances (count 0)");
  if (c->scene->instance_count + count > MAX_INSTANCES)
    return gltf_fail(c, IRIS_ERR_NOMEM, el, "%zu instances: more than %zu mesh instances in all", count, MAX_INSTANCES);
  float *t = malloc(count * 3 * sizeof(float)), *r = malloc(count * 4 * sizeof(float)),
        *s = malloc(count * 3 * sizeof(float));
  iris_status st = IRIS_OK;
  if (!t || !r || !s) st = gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory for %zu instances", count);
  static const float zero[3] = {0, 0, 0}, one[3] = {1, 1, 1}, unit_q[4] = {0, 0, 0, 1};
  if (!st) st = read_instance_attribute(c, node, "TRANSLATION", refs[0], 3, false, count, zero, t);
  if (!st) st = read_instance_attribute(c, node, "ROTATION", refs[1], 4, true, count, unit_q, r);
  if (!st) st = read_instance_attribute(c, node, "SCALE", refs[2], 3, false, count, one, s);
  for (size_t i = 0; !st && i < count; i++) {
    double q[4] = {r[4 * i], r[4 * i + 1], r[4 * i + 2], r[4 * i + 3]};
    double len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(len > 1e-6)) {
      st = gltf_fail(c, IRIS_ERR_INVALID, el, "instance %zu: ROTATION quaternion has zero length", i);
      break;
    }
    for (int k = 0; k < 4; k++) q[k] /= len;
    double x = q[0], y = q[1], z = q[2], w = q[3];
    double R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                      {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                      {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    dmat4 local = dmat4_identity();
    for (int row = 0; row < 3; row++) {
      for (int col = 0; col < 3; col++) local.m[row][col] = R[row][col] * s[3 * i + (size_t)col];
      local.m[row][3] = t[3 * i + (size_t)row];
    }
    dmat4 w4 = dmat4_mul(world, &local);
    st = add_instance_prims(c, n->mesh, &w4);
  }
  free(t);
  free(r);
  free(s);
  return st;
}

static iris_status add_light(gltf_ctx *c, int node, const dmat4 *w) {
  const iris_gltf_light *g = &c->doc->lights[c->doc->nodes[node].light];
  iris_light l;
  memset(&l, 0, sizeof l);
  l.type = strcmp(g->type, "point") == 0 ? IRIS_LIGHT_POINT
           : strcmp(g->type, "spot") == 0 ? IRIS_LIGHT_SPOT
                                          : IRIS_LIGHT_DIRECTIONAL;
  for (int k = 0; k < 3; k++) l.color[k] = g->color_len == 3 ? (float)g->color[k] : 1.0f;
  l.intensity = (float)g->intensity;
  l.range = (float)g->range;
  l.inner_cone = (float)g->inner_cone;
  l.outer_cone = (float)g->outer_cone;
  for (int k = 0; k < 3; k++) l.position[k] = (float)w->m[k][3];
  /* Lights shine along the node's local -Z (scale affects only the direction). */
  double dir[3] = {-w->m[0][2], -w->m[1][2], -w->m[2][2]};
  double len = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
  if (!(len > 1e-12) || !isfinite(len)) {
    iris_warnf("%s: node %d: light direction is degenerate (zero scale); light skipped", c->file, node);
    return IRIS_OK;
  }
  for (int k = 0; k < 3; k++) l.direction[k] = (float)(dir[k] / len);
  const char *name = g->name && g->name[0] ? g->name : c->doc->nodes[node].name;
  l.name = name && name[0] ? iris_strdup(name) : NULL;
  if (iris_scene_add_light(c->scene, &l) < 0) {
    free(l.name);
    return gltf_fail(c, IRIS_ERR_NOMEM, NULL, "out of memory");
  }
  return IRIS_OK;
}

/* Camera frame without scale: -Z (view) and +Y (up) kept, Gram-Schmidt, right-handed. */
static bool camera_frame(const dmat4 *w, iris_mat4 *out) {
  double z[3], y[3], x[3];
  for (int k = 0; k < 3; k++) z[k] = w->m[k][2], y[k] = w->m[k][1];
  double lz = sqrt(z[0] * z[0] + z[1] * z[1] + z[2] * z[2]);
  if (!(lz > 1e-12)) return false;
  for (int k = 0; k < 3; k++) z[k] /= lz;
  double dy = y[0] * z[0] + y[1] * z[1] + y[2] * z[2];
  for (int k = 0; k < 3; k++) y[k] -= dy * z[k];
  double ly = sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
  if (!(ly > 1e-12)) return false;
  for (int k = 0; k < 3; k++) y[k] /= ly;
  x[0] = y[1] * z[2] - y[2] * z[1], x[1] = y[2] * z[0] - y[0] * z[2], x[2] = y[0] * z[1] - y[1] * z[0];
  dmat4 r = dmat4_identity();
  for (int k = 0; k < 3; k++) r.m[k][0] = x[k], r.m[k][1] = y[k], r.m[k][2] = z[k], r.m[k][3] = w->m[k][3];
  *out = dmat4_to_float(&r);
  return true;
}

static const char *camera_label(gltf_ctx *c, const camera_hit *h) {
  const char *n = c->doc->cameras[h->camera].name;
  if (n && n[0]) return n;
  n = c->doc->nodes[h->node].name;
  return n && n[0] ? n : NULL;
}

static iris_status add_cameras(gltf_ctx *c, const camera_hit *hits, size_t n) {
  size_t chosen = 0;
  const char *want = c->opts ? c->opts->camera_name : NULL;
  if (want && want[0]) {
    size_t i;
    for (i = 0; i < n; i++) {
      const char *cn = c->doc->cameras[hits[i].camera].name, *nn = c->doc->nodes[hits[i].node].name;
      if ((cn && strcmp(cn, want) == 0) || (nn && strcmp(nn, want) == 0)) break;
    }
    if (i == n) {
      char list[400] = "";
      size_t used = 0;
      for (size_t k = 0; k < n && used + 1 < sizeof list; k++) {
        const char *l = camera_label(c, &hits[k]);
        int w = snprintf(list + used, sizeof list - used, "%s'%s'", k ? ", " : "", l ? l : "(unnamed)");
        if (w > 0) used += (size_t)w < sizeof list - used ? (size_t)w : sizeof list - used - 1;
      }
      return gltf_fail(c, IRIS_ERR_USAGE, "cameras", "no perspective camera named '%s' (available: %s)", want,
                  n ? list : "none");
    }
    chosen = i;
  }
  /* The chosen camera goes first; the others follow in traversal order. */
  for (size_t k = 0; k < n; k++) {
    size_t i = k == 0 ? chosen : (k <= chosen ? k - 1 : k);
    const iris_gltf_camera *g = &c->doc->cameras[hits[i].camera];
    iris_camera cam;
    memset(&cam, 0, sizeof cam);
    if (!camera_frame(&c->world[hits[i].node], &cam.to_world)) {
      iris_warnf("%s: node %d: camera transform is degenerate; camera skipped", c->file, hits[i].node);
      continue;
    }
    cam.yfov = (float)g->yfov;
    cam.aspect = (float)g->aspect;
    const char *l = camera_label(c, &hits[i]);
    cam.name = l ? iris_strdup(l) : NULL;
    if (iris_scene_add_camera(c->scene, &cam) < 0) {
      free(cam.name);
      return gltf_fail(c, IRIS_ERR_NOMEM, NULL, "out of memory");
    }
  }
  return IRIS_OK;
}

iris_status gltf_place_nodes(gltf_ctx *c) {
  const iris_gltf_doc *d = c->doc;
  size_t nn = d->node_count;
  char el[32];
  /* Roots: the default scene (or scene 0), else every parentless node. */
  const int *roots = NULL;
  size_t root_count = 0;
  int *all_roots = malloc((nn ? nn : 1) * sizeof *all_roots);
  int *stack = malloc((nn ? nn : 1) * sizeof *stack);
  camera_hit *hits = malloc((nn ? nn : 1) * sizeof *hits);
  bool *listed = calloc(nn ? nn : 1, sizeof *listed);
  c->world = malloc((nn ? nn : 1) * sizeof *c->world);
  iris_status st = IRIS_OK;
  size_t hit_count = 0;
  if (!all_roots || !stack || !hits || !listed || !c->world) {
    st = gltf_fail(c, IRIS_ERR_NOMEM, NULL, "out of memory");
    goto done;
  }
  if (d->default_scene != -1 && (d->default_scene < 0 || (size_t)d->default_scene >= d->scene_count)) {
    st = gltf_fail(c, IRIS_ERR_INVALID, "scene", "default scene %d does not exist (%zu scenes)",
              d->default_scene, d->scene_count);
    goto done;
  }
  for (size_t s = 0; s < d->scene_count; s++) /* every scene must be valid, even unused ones */
    for (size_t k = 0; k < d->scenes[s].node_count; k++) {
      int r = d->scenes[s].nodes[k];
      ELEMENT(el, "scene %zu", s);
      if (r < 0 || (size_t)r >= nn) {
        st = gltf_fail(c, IRIS_ERR_INVALID, el, "node %d does not exist (%zu nodes)", r, nn);
        goto done;
      }
      if (c->parent[r] >= 0) {
        st = gltf_fail(c, IRIS_ERR_INVALID, el, "node %d is not a root (child of node %d)", r, c->parent[r]);
        goto done;
      }
    }
  if (d->scene_count > 0) {
    size_t s = d->default_scene >= 0 ? (size_t)d->default_scene : 0;
    roots = d->scenes[s].nodes;
    root_count = d->scenes[s].node_count;
    if (d->scene_count > 1)
      iris_warnf("%s: %zu scenes; importing scene %zu only", c->file, d->scene_count, s);
  } else {
    for (size_t i = 0; i < nn; i++)
      if (c->parent[i] < 0) all_roots[root_count++] = (int)i;
    roots = all_roots;
  }
  /* Pre-order, children in order (this fixes which camera is "first"). */
  for (size_t r = 0; r < root_count; r++) {
    int root = roots[r];
    if (listed[root]) {
      ELEMENT(el, "scene");
      st = gltf_fail(c, IRIS_ERR_INVALID, el, "root node %d is listed twice", root);
      goto done;
    }
    listed[root] = true;
    dmat4 local;
    if ((st = node_local(c, (size_t)root, &local))) goto done;
    c->world[root] = local;
    size_t top = 0;
    stack[top++] = root;
    while (top > 0) {
      int ni = stack[--top];
      const iris_gltf_node *n = &d->nodes[ni];
      if (n->mesh >= 0 && n->gpu_instancing) {
        if ((st = add_gpu_instances(c, (size_t)ni, &c->world[ni]))) goto done;
      } else if (n->mesh >= 0 && (st = add_instance_prims(c, n->mesh, &c->world[ni]))) {
        goto done;
      }
      if (n->light >= 0 && (st = add_light(c, ni, &c->world[ni]))) goto done;
      if (n->camera >= 0) {
        if (strcmp(d->cameras[n->camera].type, "perspective") == 0)
          hits[hit_count++] = (camera_hit){ni, n->camera};
        else
          c->warned_ortho = true;
      }
      for (size_t k = n->child_count; k-- > 0;) {
        int ch = n->children[k];
        if ((st = node_local(c, (size_t)ch, &local))) goto done;
        c->world[ch] = dmat4_mul(&c->world[ni], &local);
        stack[top++] = ch;
      }
    }
  }
  st = add_cameras(c, hits, hit_count);
done:
  free(all_roots);
  free(stack);
  free(hits);
  free(listed);
  return st;
}
