/* validate/import_compare.h */
#include "validate/import_compare.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "core/fileio.h"
#include "scene/material_class.h"

static void note(iris_import_diff *d, const char *topic, bool geometry, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
static void note(iris_import_diff *d, const char *topic, bool geometry, const char *fmt, ...) {
  d->total++;
  if (geometry) d->geometry_differs = true;
  if (d->note_count >= IRIS_IMPORT_NOTES_MAX) return;
  iris_import_note *n = &d->notes[d->note_count++];
  snprintf(n->topic, sizeof n->topic, "%s", topic);
  n->geometry = geometry;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(n->text, sizeof n->text, fmt, ap);
  va_end(ap);
}

static double num(const cJSON *o, const char *key, double def) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  return cJSON_IsNumber(v) ? v->valuedouble : def;
}

static const char *str(const cJSON *o, const char *key) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  return cJSON_IsString(v) ? v->valuestring : "";
}

/* A Principled input: a constant (number or colour, *n components) or "linked:..." (returns 0). */
static int input(const cJSON *o, const char *key, double v[3]) {
  const cJSON *x = cJSON_GetObjectItemCaseSensitive(o, key);
  if (cJSON_IsNumber(x)) {
    v[0] = v[1] = v[2] = x->valuedouble;
    return 1;
  }
  if (cJSON_IsArray(x) && cJSON_GetArraySize(x) >= 3) {
    for (int k = 0; k < 3; k++) v[k] = cJSON_GetArrayItem(x, k)->valuedouble;
    return 3;
  }
  return 0;
}

/* A Principled input driven by a node ("linked:<bl_idname>"), e.g. a texture. */
static bool linked(const cJSON *o, const char *key) {
  return strncmp(str(o, key), "linked:", 7) == 0;
}

/* Features whose handling differs between iris and Blender 3.4's importer + Cycles, named
 * for the materials that have them (measured on StainedGlassLamp in a room:
 * docs/import-gltf.md, "A glass lamp lighting a room"). */
static void compare_features(const iris_material *m, const char *name, const cJSON *b, iris_import_diff *d) {
  double v[3];
  bool emissive = m->emission[0] > 0.0f || m->emission[1] > 0.0f || m->emission[2] > 0.0f;
  if (emissive && !m->emission_two_sided)
    note(d, "material", false,
         "material '%s': emissive and not doubleSided: iris emits from the front face only (glTF), "
         "Cycles from both faces (light from back faces, e.g. inside open bulbs, is Blender's only)", name);
  if (m->alpha_mode == IRIS_ALPHA_MASK && (linked(b, "Alpha") || (input(b, "Alpha", v) == 1 && v[0] < 1.0)))
    note(d, "material", false,
         "material '%s': alphaMode MASK: iris keeps the surface where alpha >= %g (glTF); Blender's importer "
         "feeds the alpha to Principled Alpha, which Cycles renders as stochastic transparency (no cutoff)",
         name, m->alpha_cutoff);
  /* a transmission texture iris could not keep (e.g. an image it does not decode) */
  if (m->type == IRIS_MATERIAL_GLTF && m->transmission > 0.0f && m->transmission_texture < 0 &&
      linked(b, "Transmission"))
    note(d, "material", false,
         "material '%s': Blender's importer textures Transmission (transmissionTexture); iris has no "
         "transmission texture for it and uses the factor %g alone", name, m->transmission);
  if (m->type == IRIS_MATERIAL_GLTF && m->clearcoat > 0.0f)
    note(d, "material", false,
         "material '%s': clearcoat: iris layers the coat over the base (KHR_materials_clearcoat: base x "
         "(1 - coat x Fresnel)); Blender 3.4's Principled v1 adds its Clearcoat lobe without darkening the base",
         name);
}

static void compare_geometry(const iris_scene *s, const cJSON *inv, iris_import_diff *d) {
  d->iris_triangles = iris_scene_triangle_count(s);
  d->blender_triangles = (uint64_t)num(inv, "triangles", 0);
  if (d->iris_triangles != d->blender_triangles)
    note(d, "geometry", true, "triangles: iris %llu, Blender %llu", (unsigned long long)d->iris_triangles,
         (unsigned long long)d->blender_triangles);
  iris_vec3 lo, hi;
  bool have = iris_scene_bounds(s, &lo, &hi);
  const cJSON *b = cJSON_GetObjectItemCaseSensitive(inv, "bounds");
  if (!have || !cJSON_IsArray(b) || cJSON_GetArraySize(b) != 2) {
    if (have != cJSON_IsArray(b)) note(d, "geometry", true, "one importer has geometry, the other none");
    return;
  }
  double bl[3], bh[3], il[3] = {lo.x, lo.y, lo.z}, ih[3] = {hi.x, hi.y, hi.z}, diag = 0, dev = 0;
  for (int k = 0; k < 3; k++) {
    bl[k] = cJSON_GetArrayItem(cJSON_GetArrayItem(b, 0), k)->valuedouble;
    bh[k] = cJSON_GetArrayItem(cJSON_GetArrayItem(b, 1), k)->valuedouble;
    diag += (ih[k] - il[k]) * (ih[k] - il[k]);
    dev = fmax(dev, fmax(fabs(bl[k] - il[k]), fabs(bh[k] - ih[k])));
  }
  diag = sqrt(diag);
  /* Over 2% of the diagonal is another scene; less is reported (Blender poses
   * animated nodes at their first frame, iris ignores animations). */
  if (!(dev <= 1e-4 * fmax(diag, 1e-12)))
    note(d, "geometry", !(dev <= 0.02 * fmax(diag, 1e-12)),
         "bounds (glTF axes): iris [%.6g %.6g %.6g]-[%.6g %.6g %.6g], Blender [%.6g %.6g %.6g]-[%.6g %.6g %.6g] "
         "(%.3g%% of the diagonal)",
         il[0], il[1], il[2], ih[0], ih[1], ih[2], bl[0], bl[1], bl[2], bh[0], bh[1], bh[2],
         100.0 * dev / fmax(diag, 1e-30));
}

static void compare_units(const iris_scene *s, const cJSON *inv, iris_import_diff *d) {
  double scale = num(inv, "unit_scale", 1.0);
  const char *sys = str(inv, "unit_system");
  if (fabs(scale - 1.0) > 1e-6 || (sys[0] && strcmp(sys, "METRIC") != 0))
    note(d, "units", false, "Blender's scene units are %s x %g, iris's '%s' (glTF: metres)", sys, scale,
         s->units);
}

static void compare_cameras(const iris_scene *s, const cJSON *inv, iris_import_diff *d) {
  const cJSON *cams = cJSON_GetObjectItemCaseSensitive(inv, "cameras");
  int n = cJSON_GetArraySize(cams);
  if ((size_t)n != s->camera_count)
    note(d, "camera", false, "cameras: iris %zu, Blender %d (both renders use iris's camera)", s->camera_count, n);
  for (size_t i = 0; i < s->camera_count && (int)i < n; i++) {
    const cJSON *c = cJSON_GetArrayItem(cams, (int)i);
    double ay = num(c, "angle_y", 0), ax = num(c, "angle_x", 0);
    const char *fit = str(c, "sensor_fit");
    /* With sensor_fit AUTO Blender's angle_y is the vertical angle only when the
     * image is taller than wide; the importer sets the sensor from the aspect. */
    double yf = s->cameras[i].yfov;
    bool match = fabs(ay - yf) < 1e-4 || (strcmp(fit, "VERTICAL") != 0 && fabs(ax - yf) < 1e-4 && s->cameras[i].aspect < 1);
    if (!match)
      note(d, "camera", false, "camera %zu '%s': yfov iris %.6f rad, Blender '%s' angle_y %.6f (angle_x %.6f, fit %s)",
           i, s->cameras[i].name ? s->cameras[i].name : "", yf, str(c, "name"), ay, ax, fit);
  }
}

static void compare_lights(const iris_scene *s, const cJSON *inv, iris_import_diff *d) {
  const cJSON *ls = cJSON_GetObjectItemCaseSensitive(inv, "lights");
  int n = cJSON_GetArraySize(ls);
  if ((size_t)n != s->light_count) note(d, "light", false, "lights: iris %zu, Blender %d", s->light_count, n);
  for (size_t i = 0; i < s->light_count && (int)i < n; i++) {
    const iris_light *l = &s->lights[i];
    const cJSON *b = cJSON_GetArrayItem(ls, (int)i);
    /* iris reads candela as W/sr and lux as W/m^2 (docs/materials.md); the
     * same light in Cycles has power 4 pi I (point, spot) or strength E (sun). */
    bool sun = l->type == IRIS_LIGHT_DIRECTIONAL;
    double want = sun ? l->intensity : 4.0 * 3.14159265358979323846 * l->intensity;
    double got = sun ? num(b, "strength", -1) : num(b, "power", -1);
    if (!(fabs(got - want) <= 1e-3 * fmax(want, 1e-12)))
      note(d, "light", false, "light %zu '%s' (%s): Blender's importer sets %s %.6g, iris's radiometric reading "
           "is %.6g (ratio %.4g: Blender converts photometric units, iris does not)",
           i, l->name ? l->name : "", str(b, "type"), sun ? "strength" : "power", got, want,
           want > 0 ? got / want : 0.0);
  }
}

static const cJSON *find_material(const cJSON *mats, const char *name) {
  const cJSON *m;
  cJSON_ArrayForEach(m, mats) if (strcmp(str(m, "name"), name) == 0) return m;
  return NULL;
}

static void compare_materials(const iris_scene *s, const cJSON *inv, iris_import_diff *d) {
  const cJSON *mats = cJSON_GetObjectItemCaseSensitive(inv, "materials");
  size_t coloured = 0;
  for (size_t i = 0; i < s->mesh_count; i++) coloured += s->meshes[i].colors != NULL;
  bool blender_vc = false;
  const cJSON *bm;
  cJSON_ArrayForEach(bm, mats) blender_vc = blender_vc || cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(bm, "uses_vertex_color"));
  if (coloured > 0 && !blender_vc)
    note(d, "material", false, "vertex colours: iris multiplies the base colour of %zu mesh(es) by COLOR_0, "
         "Blender's importer keeps the colours (%d mesh(es) with colour attributes) but no material uses them",
         coloured, (int)num(inv, "meshes_with_colors", 0));
  for (size_t i = 0; i < s->material_count; i++) {
    const iris_material *m = &s->materials[i];
    const char *name = m->name ? m->name : "";
    const cJSON *b = find_material(mats, name);
    if (!b) {
      /* iris names glTF's default material "glTF default"; Blender creates none. */
      if (strcmp(name, "glTF default") == 0)
        note(d, "material", false, "primitives without a material: iris uses glTF's default material (base "
             "colour 1, metallic 1, roughness 1), Blender's importer leaves them without one (Cycles' "
             "default surface, a grey diffuse)");
      else
        note(d, "material", false, "material '%s': no Blender material of that name", name);
      continue;
    }
    if (!cJSON_GetObjectItemCaseSensitive(b, "Base Color")) {
      note(d, "material", false, "material '%s': Blender built no Principled BSDF", name);
      continue;
    }
    double v[3];
    char diffs[200] = "";
    size_t len = 0;
#define DIFF(...) len += (size_t)snprintf(diffs + len, len < sizeof diffs ? sizeof diffs - len : 0, __VA_ARGS__)
    if (input(b, "Base Color", v) == 3 && m->color_texture < 0) {
      double dev = fmax(fabs(v[0] - m->color[0]), fmax(fabs(v[1] - m->color[1]), fabs(v[2] - m->color[2])));
      if (dev > 1e-4) DIFF(" base colour iris (%.4g %.4g %.4g) Blender (%.4g %.4g %.4g);", m->color[0], m->color[1], m->color[2], v[0], v[1], v[2]);
    }
    bool gltf = m->type == IRIS_MATERIAL_GLTF;
    double metallic = gltf ? m->metallic : 0.0, rough = gltf ? m->roughness : 1.0;
    if (input(b, "Metallic", v) == 1 && fabs(v[0] - metallic) > 1e-4 && !(gltf && m->metallic_roughness_texture >= 0))
      DIFF(" metallic iris %.4g Blender %.4g;", metallic, v[0]);
    if (gltf && input(b, "Roughness", v) == 1 && fabs(v[0] - rough) > 1e-4 && m->metallic_roughness_texture < 0)
      DIFF(" roughness iris %.4g Blender %.4g;", rough, v[0]);
    if (input(b, "Transmission", v) == 1 && fabs(v[0] - (gltf ? m->transmission : 0.0)) > 1e-4)
      DIFF(" transmission iris %.4g Blender %.4g;", gltf ? m->transmission : 0.0, v[0]);
    double es[3] = {0, 0, 0}, ec[3] = {0, 0, 0};
    if (input(b, "Emission Strength", es) == 1 && input(b, "Emission", ec) == 3 && m->emission_texture < 0) {
      double dev = 0;
      for (int k = 0; k < 3; k++) dev = fmax(dev, fabs(es[0] * ec[k] - m->emission[k]) / fmax(1e-6, m->emission[k]));
      if (dev > 1e-3 && (m->emission[0] + m->emission[1] + m->emission[2] > 0 || es[0] * (ec[0] + ec[1] + ec[2]) > 0))
        DIFF(" emission iris (%.4g %.4g %.4g) Blender (%.4g %.4g %.4g);", m->emission[0], m->emission[1],
             m->emission[2], es[0] * ec[0], es[0] * ec[1], es[0] * ec[2]);
    }
#undef DIFF
    if (diffs[0]) note(d, "material", false, "material '%s': parameters differ:%s", name, diffs);
    compare_features(m, name, b, d);
    /* Which BSDF each side renders: Blender's importer always builds a
     * Principled BSDF v1 (Disney diffuse, Specular = 0.5 by default). */
    double spec = input(b, "Specular", v) == 1 ? v[0] : -1;
    iris_gltf_class cls = iris_material_gltf_class(m);
    const char *what = m->type == IRIS_MATERIAL_DIFFUSE ? "Lambert (diffuse)"
                       : m->type == IRIS_MATERIAL_GLTF  ? iris_gltf_class_name(cls)
                                                        : "glossy/glass";
    note(d, "material", false,
         "material '%s': iris renders %s, Blender's importer a Principled BSDF (Specular %.3g%s): "
         "expect the residual of docs/validation.md", name, what, spec,
         m->type == IRIS_MATERIAL_DIFFUSE ? ", Disney diffuse instead of Lambert" : "");
  }
}

iris_status iris_import_compare(const iris_scene *scene, const char *inventory_path,
                                iris_import_diff *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  char *text = NULL;
  size_t size = 0;
  iris_status st = iris_file_read(inventory_path, 0, &text, &size, err);
  if (st != IRIS_OK) return st;
  cJSON *inv = cJSON_ParseWithLength(text, size);
  free(text);
  if (!cJSON_IsObject(inv)) {
    cJSON_Delete(inv);
    return iris_error_set(err, IRIS_ERR_INTERNAL, inventory_path, 0, NULL,
                          "not the JSON inventory the Blender script writes");
  }
  compare_geometry(scene, inv, out);
  compare_units(scene, inv, out);
  compare_cameras(scene, inv, out);
  compare_lights(scene, inv, out);
  compare_materials(scene, inv, out);
  cJSON_Delete(inv);
  return IRIS_OK;
}
