/* The MTL side of the OBJ importer: material libraries parsed leniently (one
 * warning listing the keys ignored), and each material used turned into an
 * iris material with its textures on first use. The mapping is in
 * docs/import-obj-ply.md ("MTL mapping"); the OBJ lines: obj.c. */
#include <stdio.h>

#include "core/cancel.h"
#include "core/fileio.h"
#include "core/log.h"
#include "importers/obj_private.h"

static const char *mime_of(const char *path) {
  char ext[16];
  iris_path_ext(path, ext, sizeof ext);
  if (!strcmp(ext, "png")) return "image/png";
  if (!strcmp(ext, "jpg") || !strcmp(ext, "jpeg")) return "image/jpeg";
  return NULL;
}

/* "map_Kd [-options args] file name": returns the resolved path or NULL. */
static char *parse_map(const char *p, const char *end, const char *mtl_dir, bool *clamp,
                       const char *mtl_path, long line) {
  static const struct {
    const char *opt;
    int args;
  } opts[] = {{"-blendu", 1}, {"-blendv", 1}, {"-bm", 1},   {"-boost", 1}, {"-cc", 1},
              {"-clamp", 1},  {"-imfchan", 1}, {"-mm", 2},  {"-o", 3},     {"-s", 3},
              {"-t", 3},      {"-texres", 1}, {"-type", 1}};
  *clamp = false;
  for (;;) {
    p = iris_np_skip_space(p, end);
    if (p >= end || *p != '-') break;
    const char *q = p;
    while (q < end && !iris_np_is_space(*q)) q++;
    size_t n = (size_t)(q - p);
    int args = -1;
    for (size_t i = 0; i < sizeof opts / sizeof opts[0]; i++)
      if (strlen(opts[i].opt) == n && !memcmp(opts[i].opt, p, n)) args = opts[i].args;
    if (args < 0) break; /* a file name starting with '-' */
    bool is_clamp = n == 6 && !memcmp(p, "-clamp", 6);
    p = q;
    for (int a = 0; a < args; a++) {
      p = iris_np_skip_space(p, end);
      const char *s = p;
      /* -o/-s/-t take 1 to 3 numbers */
      if (a > 0 && args == 3) {
        double d;
        const char *t = p;
        if (!iris_parse_double(&t, end, &d)) break;
      }
      while (p < end && !iris_np_is_space(*p)) p++;
      if (is_clamp) *clamp = (p - s == 2 && !memcmp(s, "on", 2));
    }
  }
  char name[1024];
  copy_rest(p, end, name, sizeof name);
  for (char *c = name; *c; c++)
    if (*c == '\\') *c = '/';
  if (!name[0]) {
    iris_warnf("%s:%ld: texture map without a file name ignored", mtl_path, line);
    return NULL;
  }
  char full[2048];
  iris_path_join(mtl_dir, name, full, sizeof full);
  return iris_strdup(full);
}

static iris_status parse_mtl(obj_ctx *c, const char *data, size_t size, const char *mtl_path) {
  const char *p = data, *end = data + size;
  char mtl_dir[1024];
  iris_path_dir(mtl_path, mtl_dir, sizeof mtl_dir);
  char ignored[512] = "";
  mtl_material *m = NULL;
  long line = 0;
  while (p < end) {
    const char *e = line_end(p, end);
    line++;
    if ((line & 0xffff) == 0 && iris_cancel_requested()) /* Ctrl-C: core/cancel.h */
      return iris_error_set(c->err, IRIS_ERR_INTERRUPTED, c->path, line, NULL, "interrupted while loading the scene");
    const char *le = strip_comment(p, e);
    const char *k = iris_np_skip_space(p, le);
    const char *ke = k;
    while (ke < le && !iris_np_is_space(*ke)) ke++;
    size_t kn = (size_t)(ke - k);
    const char *a = ke;
#define KEY(s) (kn == sizeof(s) - 1 && !memcmp(k, s, kn))
    if (kn == 0) {
    } else if (KEY("newmtl")) {
      if (!grow((void **)&c->mtls, &c->mtl_cap, c->mtl_count + 1, sizeof *c->mtls))
        return iris_error_set(c->err, IRIS_ERR_NOMEM, mtl_path, line, NULL, "out of memory");
      m = &c->mtls[c->mtl_count++];
      memset(m, 0, sizeof *m);
      copy_rest(a, le, m->name, sizeof m->name);
      m->kd[0] = m->kd[1] = m->kd[2] = 0.8f;
      m->ns = 0, m->ni = 1.5f, m->d = 1, m->illum = -1;
      m->scene_index = -2;
    } else if (!m) {
      note_ignored(ignored, sizeof ignored, k, kn);
    } else if (KEY("Kd") || KEY("Ks") || KEY("Ke") || KEY("Tf")) {
      float v[3];
      int n;
      const char *q = a;
      if (!parse_floats(&q, le, v, 3, &n) || n == 0) {
        /* "Kd spectral file" / "Tf xyz ..." */
        q = iris_np_skip_space(a, le);
        if (iris_np_match(q, le, "spectral") || iris_np_match(q, le, "xyz")) {
          note_ignored(ignored, sizeof ignored, k, kn);
          p = e + (e < end);
          continue;
        }
        return iris_error_set(c->err, IRIS_ERR_PARSE, mtl_path, line, NULL,
                              "expected 1 or 3 numbers after '%.*s'", (int)kn, k);
      }
      if (n == 1) v[1] = v[2] = v[0];
      if (n == 2) return iris_error_set(c->err, IRIS_ERR_PARSE, mtl_path, line, NULL,
                                        "expected 1 or 3 numbers after '%.*s'", (int)kn, k);
      if (!all_finite(v, 3) || v[0] < 0 || v[1] < 0 || v[2] < 0)
        return iris_error_set(c->err, IRIS_ERR_INVALID, mtl_path, line, m->name,
                              "'%.*s' must be finite and non-negative", (int)kn, k);
      float *dst = KEY("Kd") ? m->kd : KEY("Ks") ? m->ks : KEY("Ke") ? m->ke : m->tf;
      memcpy(dst, v, sizeof v);
      if (KEY("Tf")) m->has_tf = true;
    } else if (KEY("Ns") || KEY("Ni") || KEY("d") || KEY("Tr") || KEY("Pr") || KEY("Pm") ||
               KEY("illum")) {
      float v = 0;
      int n;
      const char *q = a;
      /* "d -halo 0.5" */
      q = iris_np_skip_space(q, le);
      if (KEY("d") && iris_np_match(q, le, "-halo")) q += 5;
      if (!parse_floats(&q, le, &v, 1, &n) || n != 1 || !isfinite(v))
        return iris_error_set(c->err, IRIS_ERR_PARSE, mtl_path, line, NULL,
                              "expected a finite number after '%.*s'", (int)kn, k);
      if (KEY("Ns")) m->ns = v;
      else if (KEY("Ni")) m->ni = v, m->has_ni = true;
      else if (KEY("d")) m->d = v;
      else if (KEY("Tr")) m->d = 1.0f - v;
      else if (KEY("Pr")) m->pr = v, m->has_pr = true;
      else if (KEY("Pm")) m->pm = v, m->has_pm = true;
      else m->illum = (int)v;
    } else if (KEY("map_Kd") || KEY("map_Ke")) {
      bool clamp;
      char *path = parse_map(a, le, mtl_dir, &clamp, mtl_path, line);
      if (KEY("map_Kd")) free(m->map_kd), m->map_kd = path, m->map_kd_clamp = clamp;
      else free(m->map_ke), m->map_ke = path, m->map_ke_clamp = clamp;
    } else {
      /* Ka, map_Ka, map_Ks, map_Ns, map_d, bump, map_bump, norm, disp, decal,
       * refl, sharpness, Ps, Pc, Pcr, aniso, anisor, map_Pr, map_Pm, ... */
      note_ignored(ignored, sizeof ignored, k, kn);
    }
#undef KEY
    p = e + (e < end);
  }
  if (ignored[0]) iris_warnf("%s: MTL keys ignored: %s", mtl_path, ignored);
  return IRIS_OK;
}

void obj_load_mtllib(obj_ctx *c, const char *a, const char *le, long line) {
  if (!c->dir) return; /* parsing from memory without a folder */
  char names[1024];
  copy_rest(a, le, names, sizeof names);
  /* Usually one file; several are separated by spaces. Try the whole string
   * first (names with spaces), then each word. */
  char full[2048];
  iris_path_join(c->dir, names, full, sizeof full);
  const char *list[16];
  int count = 0;
  char *save = NULL;
  if (iris_path_exists(full)) {
    list[count++] = names;
  } else {
    for (char *t = strtok_r(names, " \t", &save); t && count < 16; t = strtok_r(NULL, " \t", &save))
      list[count++] = t;
  }
  for (int i = 0; i < count; i++) {
    char nm[1024];
    snprintf(nm, sizeof nm, "%s", list[i]);
    for (char *ch = nm; *ch; ch++)
      if (*ch == '\\') *ch = '/';
    iris_path_join(c->dir, nm, full, sizeof full);
    if (iris_strmap_find(&c->mtllib_map, full)) continue; /* read once, however often named */
    iris_strmap_put(&c->mtllib_map, full, 0);
    char *data = NULL;
    size_t size = 0;
    iris_error e;
    iris_error_clear(&e);
    if (iris_file_read(full, (size_t)1 << 28, &data, &size, &e) != IRIS_OK) {
      iris_warnf("%s:%ld: cannot read material library '%s'; its materials get the default", c->path,
                 line, nm);
      continue;
    }
    parse_mtl(c, data, size, full);
    free(data);
  }
}

/* ---- materials into the scene ------------------------------------------ */

static int32_t add_texture(obj_ctx *c, const char *path, bool clamp) {
  char key[4096];
  snprintf(key, sizeof key, "%d%s", clamp ? 1 : 0, path);
  const int32_t *found = iris_strmap_find(&c->texture_map, key);
  if (found) return *found;
  const char *mime = mime_of(path);
  if (!mime) {
    iris_warnf("%s: texture '%s' ignored: only PNG and JPEG are supported", c->path, path);
    return -1;
  }
  if (!iris_path_exists(path)) {
    iris_warnf("%s: texture '%s' not found; ignored", c->path, path);
    return -1;
  }
  iris_texture t;
  memset(&t, 0, sizeof t);
  t.path = iris_strdup(path);
  snprintf(t.mime, sizeof t.mime, "%s", mime);
  t.wrap_s = t.wrap_t = clamp ? IRIS_WRAP_CLAMP : IRIS_WRAP_REPEAT;
  if (!t.path) return -1;
  const int32_t id = iris_scene_add_texture(c->scene, &t);
  if (id >= 0) iris_strmap_put(&c->texture_map, key, id);
  return id;
}

static float maxf3(const float *v) {
  float m = v[0] > v[1] ? v[0] : v[1];
  return m > v[2] ? m : v[2];
}

/* The MTL -> iris material mapping (docs/import-obj-ply.md, "MTL mapping"). */
static iris_material material_from_mtl(obj_ctx *c, const mtl_material *m) {
  const float ns = m->ns < 0 ? 0 : (m->ns > 1e6f ? 1e6f : m->ns);
  /* Blinn-Phong exponent -> Beckmann/GGX alpha (Walter et al. 2007), roughness = sqrt(alpha). */
  const float ns_roughness = sqrtf(sqrtf(2.0f / (ns + 2.0f)));
  const float ior = (m->has_ni && m->ni > 1.0f) ? m->ni : 1.5f;
  const bool glass = m->illum == 4 || m->illum == 6 || m->illum == 7 || m->illum == 9 || m->d < 1.0f;
  iris_material mat;
  if (glass) {
    mat = iris_material_default(IRIS_MATERIAL_GLASS);
    if (m->has_tf) memcpy(mat.color, m->tf, sizeof mat.color);
    else mat.color[0] = mat.color[1] = mat.color[2] = 1.0f;
    mat.roughness = 0.0f;
    mat.ior = ior;
  } else if (m->has_pr || m->has_pm) {
    mat = iris_material_default(IRIS_MATERIAL_GLTF);
    memcpy(mat.color, m->kd, sizeof mat.color);
    mat.roughness = m->has_pr ? fminf(fmaxf(m->pr, 0), 1) : ns_roughness;
    mat.metallic = m->has_pm ? fminf(fmaxf(m->pm, 0), 1) : 0;
    mat.ior = ior;
  } else if (maxf3(m->ks) > 0) {
    if (maxf3(m->kd) > 0) {
      /* Diffuse + specular: a dielectric glTF material whose normal-incidence
       * reflectance F0 = 0.04 * specular_color equals Ks. */
      mat = iris_material_default(IRIS_MATERIAL_GLTF);
      memcpy(mat.color, m->kd, sizeof mat.color);
      mat.roughness = ns_roughness;
      mat.metallic = 0;
      mat.ior = 1.5f;
      mat.specular = 1;
      for (int i = 0; i < 3; i++) mat.specular_color[i] = fminf(m->ks[i], 1.0f) / 0.04f;
    } else {
      mat = iris_material_default(IRIS_MATERIAL_GLOSSY);
      memcpy(mat.color, m->ks, sizeof mat.color);
      mat.roughness = ns_roughness;
    }
  } else {
    mat = iris_material_default(IRIS_MATERIAL_DIFFUSE);
    memcpy(mat.color, m->kd, sizeof mat.color);
  }
  mat.name = iris_strdup(m->name);
  if (maxf3(m->ke) > 0) {
    memcpy(mat.emission, m->ke, sizeof mat.emission);
    mat.emission_two_sided = true;
  }
  if (m->map_kd && !glass) mat.color_texture = add_texture(c, m->map_kd, m->map_kd_clamp);
  if (m->map_ke) {
    mat.emission_texture = add_texture(c, m->map_ke, m->map_ke_clamp);
    if (mat.emission_texture >= 0 && maxf3(m->ke) <= 0)
      mat.emission[0] = mat.emission[1] = mat.emission[2] = 1.0f, mat.emission_two_sided = true;
  }
  return mat;
}

/* Scene material index for a usemtl name; -1 (default) for none/unknown. */
int32_t obj_resolve_material(obj_ctx *c, const char *name, bool *warned) {
  if (!name[0]) return -1;
  if (!c->mtl_map_built) { /* the last definition wins */
    for (size_t i = 0; i < c->mtl_count && i < INT32_MAX; i++) iris_strmap_put(&c->mtl_map, c->mtls[i].name, (int32_t)i);
    c->mtl_map_built = true;
  }
  const int32_t *found = iris_strmap_find(&c->mtl_map, name);
  if (found) {
    mtl_material *m = &c->mtls[*found];
    if (m->scene_index == -2) {
      iris_material mat = material_from_mtl(c, m);
      m->scene_index = iris_scene_add_material(c->scene, &mat);
    }
    return m->scene_index;
  }
  if (!*warned) {
    iris_warnf("%s: material '%s' is not defined%s; the default material is used", c->path, name,
               c->dir ? "" : " (material libraries are not read from memory)");
    *warned = true;
  }
  return -1;
}
