/* glTF 2.0 import, materials: samplers, images and textures, and the
 * metallic-roughness material of Appendix B with the KHR_materials_* and
 * KHR_texture_transform extensions, into iris materials and textures.
 * Mapping decisions are documented in docs/import-gltf.md. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/fileio.h"
#include "core/log.h"
#include "importers/gltf_private.h"
#include "importers/webp.h"

iris_status gltf_validate_textures(gltf_ctx *c) {
  const iris_gltf_doc *d = c->doc;
  char el[64];
  for (size_t i = 0; i < d->sampler_count; i++) {
    const iris_gltf_sampler *s = &d->samplers[i];
    ELEMENT(el, "sampler %zu", i);
    int wraps[2] = {s->wrap_s, s->wrap_t};
    for (int k = 0; k < 2; k++)
      if (wraps[k] != WRAP_REPEAT && wraps[k] != WRAP_CLAMP && wraps[k] != WRAP_MIRROR)
        return gltf_fail(c, IRIS_ERR_INVALID, el, "invalid wrap mode %d", wraps[k]);
    if (s->mag_filter != -1 && s->mag_filter != FILTER_NEAREST && s->mag_filter != FILTER_LINEAR)
      return gltf_fail(c, IRIS_ERR_INVALID, el, "invalid magFilter %d", s->mag_filter);
  }
  for (size_t i = 0; i < d->image_count; i++) {
    const iris_gltf_image *im = &d->images[i];
    ELEMENT(el, "image %zu", i);
    if (im->view != -1 && (im->view < 0 || (size_t)im->view >= d->view_count))
      return gltf_fail(c, IRIS_ERR_INVALID, el, "bufferView %d does not exist", im->view);
  }
  for (size_t i = 0; i < d->texture_count; i++) {
    const iris_gltf_texture *t = &d->textures[i];
    ELEMENT(el, "texture %zu", i);
    if (t->source != -1 && (t->source < 0 || (size_t)t->source >= d->image_count))
      return gltf_fail(c, IRIS_ERR_INVALID, el, "image %d does not exist (%zu images)", t->source,
                  d->image_count);
    if (t->bad_extension)
      return gltf_fail(c, IRIS_ERR_INVALID, el, "%s: source is not an integer", t->bad_extension);
    int ext_sources[2] = {t->webp_source, t->basisu_source};
    for (int k = 0; k < 2; k++)
      if (ext_sources[k] != -1 && (ext_sources[k] < 0 || (size_t)ext_sources[k] >= d->image_count))
        return gltf_fail(c, IRIS_ERR_INVALID, el, "%s: image %d does not exist (%zu images)",
                         k ? "KHR_texture_basisu" : "EXT_texture_webp", ext_sources[k], d->image_count);
    if (t->sampler != -1 && (t->sampler < 0 || (size_t)t->sampler >= d->sampler_count))
      return gltf_fail(c, IRIS_ERR_INVALID, el, "sampler %d does not exist (%zu samplers)", t->sampler,
                  d->sampler_count);
  }
  return IRIS_OK;
}

static int hexval(char ch) {
  if (ch >= '0' && ch <= '9') return ch - '0';
  if (ch >= 'a' && ch <= 'f') return ch - 'a' + 10;
  if (ch >= 'A' && ch <= 'F') return ch - 'A' + 10;
  return -1;
}

/* Percent-decoding of a relative URI reference (RFC 3986). */
static void uri_decode(const char *in, char *out, size_t size) {
  size_t o = 0;
  for (size_t i = 0; in[i] && o + 1 < size; i++) {
    int h, l;
    if (in[i] == '%' && (h = hexval(in[i + 1])) >= 0 && (l = hexval(in[i + 2])) >= 0) {
      out[o++] = (char)(h * 16 + l);
      i += 2;
    } else {
      out[o++] = in[i];
    }
  }
  out[o] = '\0';
}

static void warn_dropped_image(gltf_ctx *c, size_t image, const char *why) {
  iris_warnf("%s: image %zu: %s; the texture is ignored", c->file, image, why);
  c->warned_bad_image = true;
}

static bool same_mapping(const gltf_slot *a, const gltf_slot *b) {
  if (a->uv_set != b->uv_set || a->has_transform != b->has_transform) return false;
  return !a->has_transform || (a->offset[0] == b->offset[0] && a->offset[1] == b->offset[1] &&
                               a->rotation == b->rotation && a->scale[0] == b->scale[0] &&
                               a->scale[1] == b->scale[1]);
}

/* Reads glTF image `image` into tex (data or path, and mime). A WebP image
 * is decoded and stored as PNG (importers/webp.h). *soft is set, and tex left
 * empty, when the image cannot be used: `webp_failed` tells whether it was a
 * WebP that did not decode (an error unless a fallback exists) rather than a
 * format iris does not read (the texture is dropped with a warning). */
static iris_status load_image(gltf_ctx *c, int image, iris_texture *tex, char *soft, size_t soft_size,
                              bool *webp_failed) {
  const iris_gltf_doc *d = c->doc;
  char el[64];
  const iris_gltf_image *im = &d->images[image];
  ELEMENT(el, "image %d", image);
  soft[0] = '\0';
  *webp_failed = false;
  const uint8_t *bytes = NULL;
  size_t size = 0;
  char *file_data = NULL;
  char mime[16] = "";
  if (im->view >= 0) {
    const iris_gltf_view *v = &d->views[im->view];
    bytes = d->buffers[v->buffer].data + v->offset;
    size = v->length;
  } else if (im->data) {
    bytes = im->data;
    size = im->size;
  }
  if (!bytes && im->uri) {
    if (strstr(im->uri, "://"))
      return gltf_fail(c, IRIS_ERR_UNSUPPORTED, el, "remote image URI '%s'", im->uri);
    if (!d->base_dir)
      return gltf_fail(c, IRIS_ERR_IO, el, "external image '%s' needs a file path", im->uri);
    char rel[1024], joined[2048], abs_path[4096];
    uri_decode(im->uri, rel, sizeof rel);
    iris_path_join(d->base_dir, rel, joined, sizeof joined);
    if (!im->file_found) return gltf_fail(c, IRIS_ERR_IO, el, "cannot open image file '%s'", joined);
    if (strcmp(im->file_mime, "image/webp") == 0) {
      /* Decoded like an embedded WebP; the scene then holds the PNG. */
      iris_error fe;
      iris_error_clear(&fe);
      if (iris_file_read(joined, (size_t)1 << 30, &file_data, &size, &fe) != IRIS_OK)
        return gltf_fail(c, IRIS_ERR_IO, el, "cannot read image file '%s'", joined);
      bytes = (const uint8_t *)file_data;
    } else {
      /* Absolute, so the scene stays valid wherever it is written. */
      char cwd[2048];
      if (joined[0] == '/' || !getcwd(cwd, sizeof cwd))
        snprintf(abs_path, sizeof abs_path, "%s", joined);
      else
        snprintf(abs_path, sizeof abs_path, "%s/%s", cwd, joined[0] == '.' && joined[1] == '/' ? joined + 2 : joined);
      if (!im->file_mime[0]) {
        snprintf(soft, soft_size, "not a PNG, JPEG or WebP file");
        return IRIS_OK;
      }
      tex->path = iris_strdup(abs_path);
      if (!tex->path) return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
      snprintf(tex->mime, sizeof tex->mime, "%s", im->file_mime);
      return IRIS_OK;
    }
  }
  if (!bytes) return gltf_fail(c, IRIS_ERR_INVALID, el, "has no data");
  if (iris_webp_sniff(bytes, size)) {
    uint8_t *png = NULL;
    size_t png_size = 0;
    bool ok = iris_webp_to_png(bytes, size, &png, &png_size, soft, soft_size);
    free(file_data);
    if (!ok) {
      *webp_failed = true;
      return IRIS_OK;
    }
    tex->data = png;
    tex->data_size = png_size;
    snprintf(tex->mime, sizeof tex->mime, "image/png");
    return IRIS_OK;
  }
  if (size >= 8 && memcmp(bytes, "\x89PNG\r\n\x1a\n", 8) == 0) snprintf(mime, sizeof mime, "image/png");
  else if (size >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF)
    snprintf(mime, sizeof mime, "image/jpeg");
  if (!mime[0]) {
    free(file_data);
    snprintf(soft, soft_size, "not a PNG, JPEG or WebP image");
    return IRIS_OK;
  }
  tex->data = malloc(size);
  if (!tex->data) {
    free(file_data);
    return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
  }
  memcpy(tex->data, bytes, size);
  tex->data_size = size;
  free(file_data);
  snprintf(tex->mime, sizeof tex->mime, "%s", mime);
  return IRIS_OK;
}

/* Scene texture for a material slot, created on first use: one per (image,
 * sampler, uv set, transform); -2 when dropped with a warning. The image is
 * EXT_texture_webp's source when there is one, else (or when that WebP does
 * not decode) the core source; KHR_texture_basisu's KTX2 image is never
 * decoded: its fallback source is used with a notice. */
static iris_status resolve_texture(gltf_ctx *c, const gltf_slot *slot, int32_t *out) {
  const iris_gltf_doc *d = c->doc;
  int ti = slot->texture;
  const iris_gltf_texture *t = &d->textures[ti];
  *out = -2;
  int order[2], n = 0;
  if (t->webp_source >= 0) order[n++] = t->webp_source;
  if (t->source >= 0 && t->source != t->webp_source) order[n++] = t->source;
  if (t->basisu_source >= 0 && !c->noticed_basisu) {
    c->noticed_basisu = true;
    if (t->source >= 0)
      iris_infof("%s: texture %d: KHR_texture_basisu (KTX2) cannot be decoded by iris; using its fallback image %d",
                 c->file, ti, t->source);
  }
  if (n == 0) {
    iris_warnf("%s: texture %d has no image iris can decode (%s); ignored", c->file, ti,
               t->basisu_source >= 0 ? "only KHR_texture_basisu's KTX2" : "no source");
    return IRIS_OK;
  }
  for (size_t k = 0; k < c->tex_key_count; k++) {
    const gltf_tex_key *key = &c->tex_keys[k];
    if (key->source == order[0] && key->sampler == t->sampler && same_mapping(&key->map, slot)) {
      *out = key->id;
      return IRIS_OK;
    }
  }
  if (c->tex_key_count == c->tex_key_cap) {
    size_t cap = c->tex_key_cap ? 2 * c->tex_key_cap : 8;
    gltf_tex_key *grown = realloc(c->tex_keys, cap * sizeof *grown);
    if (!grown) return gltf_fail(c, IRIS_ERR_NOMEM, NULL, "out of memory");
    c->tex_keys = grown, c->tex_key_cap = cap;
  }
  gltf_tex_key *key = &c->tex_keys[c->tex_key_count++];
  key->source = order[0], key->sampler = t->sampler, key->map = *slot, key->id = -2;
  iris_texture tex;
  memset(&tex, 0, sizeof tex);
  int used = -1;
  for (int k = 0; k < n && used < 0; k++) {
    char soft[256];
    bool webp_failed;
    iris_status st = load_image(c, order[k], &tex, soft, sizeof soft, &webp_failed);
    if (st != IRIS_OK) return st;
    if (!soft[0]) {
      used = order[k];
    } else if (k + 1 < n) {
      iris_infof("%s: image %d: %s; texture %d uses its fallback image %d", c->file, order[k], soft, ti, order[k + 1]);
    } else if (webp_failed) {
      char el[64];
      ELEMENT(el, "image %d", order[k]);
      return gltf_fail(c, IRIS_ERR_PARSE, el, "%s", soft);
    } else {
      warn_dropped_image(c, (size_t)order[k], soft);
      return IRIS_OK;
    }
  }
  const iris_gltf_image *im = &d->images[used];
  tex.name = im->name && im->name[0] ? iris_strdup(im->name) : NULL;
  tex.wrap_s = tex.wrap_t = IRIS_WRAP_REPEAT;
  if (t->sampler >= 0) {
    const iris_gltf_sampler *s = &d->samplers[t->sampler];
    int w[2] = {s->wrap_s, s->wrap_t};
    iris_wrap *dst[2] = {&tex.wrap_s, &tex.wrap_t};
    for (int k = 0; k < 2; k++)
      *dst[k] = w[k] == WRAP_CLAMP ? IRIS_WRAP_CLAMP : w[k] == WRAP_MIRROR ? IRIS_WRAP_MIRROR : IRIS_WRAP_REPEAT;
    tex.nearest = s->mag_filter == FILTER_NEAREST;
  }
  tex.uv_set = slot->uv_set;
  tex.has_transform = slot->has_transform;
  memcpy(tex.offset, slot->offset, sizeof tex.offset);
  tex.rotation = slot->rotation;
  memcpy(tex.scale, slot->scale, sizeof tex.scale);
  int32_t id = iris_scene_add_texture(c->scene, &tex);
  if (id < 0) {
    free(tex.name), free(tex.path), free(tex.data);
    return gltf_fail(c, IRIS_ERR_NOMEM, NULL, "out of memory");
  }
  *out = key->id = id;
  return IRIS_OK;
}

iris_status gltf_check_range(gltf_ctx *c, const char *el, const char *what, double v, double lo, double hi) {
  if (!isfinite(v) || v < lo || v > hi)
    return gltf_fail(c, IRIS_ERR_INVALID, el, "%s %g is not in [%g, %g]", what, v, lo, hi);
  return IRIS_OK;
}

/* Texture reference check: index in range, texCoord 0 or 1 (higher sets are
 * dropped with a warning), KHR_texture_transform values finite (its texCoord
 * overrides the textureInfo's). Fills the slot and *out (the glTF index, or -1). */
static iris_status texture_ref(gltf_ctx *c, const char *el, const char *what, iris_gltf_texture_ref r,
                               gltf_slot *slot, int32_t *out) {
  *out = -1;
  memset(slot, 0, sizeof *slot);
  slot->texture = -1;
  if (r.texture == -1) return IRIS_OK;
  if (r.texture < 0 || (size_t)r.texture >= c->doc->texture_count)
    return gltf_fail(c, IRIS_ERR_INVALID, el, "%s: texture %d does not exist (%zu textures)", what,
                r.texture, c->doc->texture_count);
  if (r.texcoord < 0) return gltf_fail(c, IRIS_ERR_INVALID, el, "%s: negative texCoord", what);
  if (r.bad_transform)
    return gltf_fail(c, IRIS_ERR_INVALID, el, "%s: KHR_texture_transform: a value has the wrong JSON type",
                     what);
  int set = r.has_transform && r.transform_texcoord >= 0 ? r.transform_texcoord : r.texcoord;
  if (r.has_transform) {
    double v[5] = {r.offset[0], r.offset[1], r.rotation, r.tscale[0], r.tscale[1]};
    for (int k = 0; k < 5; k++)
      if (!isfinite(v[k]) || fabs(v[k]) > 3.4e38)
        return gltf_fail(c, IRIS_ERR_INVALID, el, "%s: KHR_texture_transform value %g is not finite", what,
                         v[k]);
    slot->has_transform = r.offset[0] != 0 || r.offset[1] != 0 || r.rotation != 0 || r.tscale[0] != 1 ||
                          r.tscale[1] != 1;
    slot->offset[0] = (float)r.offset[0], slot->offset[1] = (float)r.offset[1];
    slot->rotation = (float)r.rotation;
    slot->scale[0] = (float)r.tscale[0], slot->scale[1] = (float)r.tscale[1];
  }
  if (set > 1) { /* valid glTF, but iris keeps two uv sets */
    c->warned_texcoord = true;
    return IRIS_OK;
  }
  slot->uv_set = (uint8_t)set;
  slot->texture = r.texture;
  *out = r.texture; /* glTF index; turned into a scene index when the material is used */
  return IRIS_OK;
}

int gltf_material_normal_uv_set(const gltf_ctx *c, int gi) {
  if (gi < 0) return -1;
  if (c->slots[gi][GLTF_SLOT_NORMAL].texture >= 0) return c->slots[gi][GLTF_SLOT_NORMAL].uv_set;
  if (c->slots[gi][GLTF_SLOT_CLEARCOAT_NORMAL].texture >= 0) return c->slots[gi][GLTF_SLOT_CLEARCOAT_NORMAL].uv_set;
  return -1;
}

int gltf_material_tangent_uv_set(const gltf_ctx *c, int gi) {
  int set = gltf_material_normal_uv_set(c, gi);
  if (set >= 0 || gi < 0) return set;
  const iris_material *m = &c->materials[gi];
  if (!(m->anisotropy > 0.0f)) return -1;
  const gltf_slot *a = &c->slots[gi][GLTF_SLOT_ANISOTROPY];
  return a->texture >= 0 ? a->uv_set : 0;
}

iris_alpha_mode gltf_material_alpha_mode(const gltf_ctx *c, int gi) {
  return gi < 0 ? IRIS_ALPHA_OPAQUE : c->materials[gi].alpha_mode;
}

bool gltf_material_uses_uv1(const gltf_ctx *c, int gi) {
  if (gi < 0) return false;
  for (int k = 0; k < GLTF_SLOT_COUNT; k++)
    if (c->slots[gi][k].texture >= 0 && c->slots[gi][k].uv_set == 1) return true;
  return false;
}

/* glTF 2.0 Appendix B metallic-roughness material (+ the KHR_materials_* above). */
iris_status gltf_validate_materials(gltf_ctx *c) {
  const iris_gltf_doc *d = c->doc;
  c->materials = calloc(d->material_count ? d->material_count : 1, sizeof *c->materials);
  c->slots = calloc(d->material_count ? d->material_count : 1, sizeof *c->slots);
  if (!c->materials || !c->slots) return gltf_fail(c, IRIS_ERR_NOMEM, NULL, "out of memory");
  char el[64];
  iris_status st;
  for (size_t i = 0; i < d->material_count; i++) {
    const iris_gltf_material *g = &d->materials[i];
    iris_material *m = &c->materials[i];
    ELEMENT(el, "material %zu", i);
    *m = iris_material_default(IRIS_MATERIAL_GLTF);
    if (g->bad_extension)
      return gltf_fail(c, IRIS_ERR_INVALID, el, "%s: a value has the wrong JSON type", g->bad_extension);
    if (g->base_color_len != 4)
      return gltf_fail(c, IRIS_ERR_INVALID, el, "baseColorFactor has %zu values (4 expected)", g->base_color_len);
    if (g->emissive_len != 3)
      return gltf_fail(c, IRIS_ERR_INVALID, el, "emissiveFactor has %zu values (3 expected)", g->emissive_len);
    for (int k = 0; k < 4; k++)
      if ((st = gltf_check_range(c, el, "baseColorFactor component", g->base_color[k], 0, 1))) return st;
    for (int k = 0; k < 3; k++)
      if ((st = gltf_check_range(c, el, "emissiveFactor component", g->emissive[k], 0, 1))) return st;
    if ((st = gltf_check_range(c, el, "metallicFactor", g->metallic, 0, 1)) ||
        (st = gltf_check_range(c, el, "roughnessFactor", g->roughness, 0, 1)) ||
        (st = gltf_check_range(c, el, "KHR_materials_emissive_strength emissiveStrength",
                          g->emissive_strength, 0, HUGE_VAL)) ||
        (st = gltf_check_range(c, el, "KHR_materials_specular specularFactor", g->specular, 0, 1)) ||
        (st = gltf_check_range(c, el, "KHR_materials_transmission transmissionFactor", g->transmission, 0, 1)))
      return st;
    for (int k = 0; k < 3; k++)
      if ((st = gltf_check_range(c, el, "KHR_materials_specular specularColorFactor component",
                            g->specular_color[k], 0, HUGE_VAL)))
        return st;
    if (!isfinite(g->ior) || (g->ior != 0.0 && g->ior < 1.0))
      return gltf_fail(c, IRIS_ERR_INVALID, el, "KHR_materials_ior ior %g is neither 0 nor >= 1", g->ior);

    if (g->name && g->name[0]) m->name = (char *)g->name; /* copied when added */
    for (int k = 0; k < 3; k++) {
      m->color[k] = (float)g->base_color[k];
      m->emission[k] = (float)(g->emissive[k] * g->emissive_strength);
      m->specular_color[k] = (float)g->specular_color[k];
    }
    m->metallic = (float)g->metallic;
    m->roughness = (float)g->roughness;
    m->specular = (float)g->specular;
    m->transmission = (float)g->transmission;
    /* ior 0 is the extension's "F0 = 1" special case, which a dielectric cannot express. */
    if (g->ior == 0.0) iris_warnf("%s: material %zu: KHR_materials_ior ior 0 is not supported; using 1.5", c->file, i);
    m->ior = g->ior == 0.0 ? 1.5f : (float)g->ior;
    m->double_sided = g->double_sided;
    m->emission_two_sided = g->double_sided;
    gltf_slot *slots = c->slots[i];
    for (int k = 0; k < GLTF_SLOT_COUNT; k++) slots[k].texture = -1;
    if ((st = texture_ref(c, el, "baseColorTexture", g->base_color_texture, &slots[GLTF_SLOT_COLOR],
                          &m->color_texture)) ||
        (st = texture_ref(c, el, "metallicRoughnessTexture", g->metallic_roughness_texture,
                          &slots[GLTF_SLOT_METALLIC_ROUGHNESS], &m->metallic_roughness_texture)) ||
        (st = texture_ref(c, el, "emissiveTexture", g->emissive_texture, &slots[GLTF_SLOT_EMISSION],
                          &m->emission_texture)))
      return st;
    if ((st = texture_ref(c, el, "normalTexture", g->normal_texture, &slots[GLTF_SLOT_NORMAL],
                          &m->normal_texture)))
      return st;
    /* KHR_materials_transmission: factor x R; KHR_materials_specular: factor x A, colour x RGB */
    if ((st = texture_ref(c, el, "transmissionTexture", g->transmission_texture, &slots[GLTF_SLOT_TRANSMISSION],
                          &m->transmission_texture)) ||
        (st = texture_ref(c, el, "specularTexture", g->specular_texture, &slots[GLTF_SLOT_SPECULAR],
                          &m->specular_texture)) ||
        (st = texture_ref(c, el, "specularColorTexture", g->specular_color_texture,
                          &slots[GLTF_SLOT_SPECULAR_COLOR], &m->specular_color_texture)))
      return st;
    if (g->has_clearcoat) { /* KHR_materials_clearcoat */
      if ((st = gltf_check_range(c, el, "KHR_materials_clearcoat clearcoatFactor", g->clearcoat, 0, 1)) ||
          (st = gltf_check_range(c, el, "KHR_materials_clearcoat clearcoatRoughnessFactor",
                                 g->clearcoat_roughness, 0, 1)) ||
          (st = texture_ref(c, el, "clearcoatTexture", g->clearcoat_texture, &slots[GLTF_SLOT_CLEARCOAT],
                            &m->clearcoat_texture)) ||
          (st = texture_ref(c, el, "clearcoatRoughnessTexture", g->clearcoat_roughness_texture,
                            &slots[GLTF_SLOT_CLEARCOAT_ROUGHNESS], &m->clearcoat_roughness_texture)) ||
          (st = texture_ref(c, el, "clearcoatNormalTexture", g->clearcoat_normal_texture,
                            &slots[GLTF_SLOT_CLEARCOAT_NORMAL], &m->clearcoat_normal_texture)))
        return st;
      if (!isfinite(g->clearcoat_normal_texture.scale))
        return gltf_fail(c, IRIS_ERR_INVALID, el, "clearcoatNormalTexture scale is not finite");
      m->clearcoat = (float)g->clearcoat;
      m->clearcoat_roughness = (float)g->clearcoat_roughness;
      m->clearcoat_normal_scale = (float)g->clearcoat_normal_texture.scale;
    }
    if (g->has_volume) { /* KHR_materials_volume: the attenuation (thickness is for rasterisers) */
      for (int k = 0; k < 3; k++)
        if ((st = gltf_check_range(c, el, "KHR_materials_volume attenuationColor component",
                                   g->attenuation_color[k], 0, 1)))
          return st;
      if (g->has_attenuation_distance && (!isfinite(g->attenuation_distance) || !(g->attenuation_distance > 0)))
        return gltf_fail(c, IRIS_ERR_INVALID, el, "KHR_materials_volume attenuationDistance %g is not > 0",
                         g->attenuation_distance);
      if (g->has_attenuation_distance && g->attenuation_distance < 3.4e38) {
        m->attenuation_distance = (float)g->attenuation_distance;
        for (int k = 0; k < 3; k++) m->attenuation_color[k] = (float)g->attenuation_color[k];
      }
    }
    if (g->has_sheen) { /* KHR_materials_sheen */
      for (int k = 0; k < 3; k++)
        if ((st = gltf_check_range(c, el, "KHR_materials_sheen sheenColorFactor component", g->sheen_color[k], 0, 1)))
          return st;
      if ((st = gltf_check_range(c, el, "KHR_materials_sheen sheenRoughnessFactor", g->sheen_roughness, 0, 1)) ||
          (st = texture_ref(c, el, "sheenColorTexture", g->sheen_color_texture, &slots[GLTF_SLOT_SHEEN_COLOR],
                            &m->sheen_color_texture)) ||
          (st = texture_ref(c, el, "sheenRoughnessTexture", g->sheen_roughness_texture,
                            &slots[GLTF_SLOT_SHEEN_ROUGHNESS], &m->sheen_roughness_texture)))
        return st;
      for (int k = 0; k < 3; k++) m->sheen_color[k] = (float)g->sheen_color[k];
      m->sheen_roughness = (float)g->sheen_roughness;
    }
    if (g->has_anisotropy) { /* KHR_materials_anisotropy */
      if ((st = gltf_check_range(c, el, "KHR_materials_anisotropy anisotropyStrength", g->anisotropy_strength, 0, 1)))
        return st;
      if (!isfinite(g->anisotropy_rotation) || fabs(g->anisotropy_rotation) > 3.4e38)
        return gltf_fail(c, IRIS_ERR_INVALID, el, "KHR_materials_anisotropy anisotropyRotation %g is not a finite float",
                         g->anisotropy_rotation);
      if ((st = texture_ref(c, el, "anisotropyTexture", g->anisotropy_texture, &slots[GLTF_SLOT_ANISOTROPY],
                            &m->anisotropy_texture)))
        return st;
      m->anisotropy = (float)g->anisotropy_strength;
      m->anisotropy_rotation = (float)g->anisotropy_rotation;
    }
    if (g->has_dispersion) { /* named in one warning at the end (gltf_convert.c) */
      size_t n = strlen(c->dispersion_materials);
      if (n + 80 < sizeof c->dispersion_materials) {
        if (g->name && g->name[0])
          snprintf(c->dispersion_materials + n, sizeof c->dispersion_materials - n, "%s'%s'", n ? ", " : "", g->name);
        else
          snprintf(c->dispersion_materials + n, sizeof c->dispersion_materials - n, "%s%zu", n ? ", " : "", i);
      } else if (n + 5 < sizeof c->dispersion_materials && strcmp(c->dispersion_materials + n - 3, "...") != 0) {
        snprintf(c->dispersion_materials + n, sizeof c->dispersion_materials - n, ", ...");
      }
      c->dispersion_count++;
    }
    if (!isfinite(g->normal_texture.scale) || fabs(g->normal_texture.scale) > 3.4e38)
      return gltf_fail(c, IRIS_ERR_INVALID, el, "normalTexture scale %g is not finite", g->normal_texture.scale);
    m->normal_scale = (float)g->normal_texture.scale;
    if (g->alpha_mode && g->alpha_mode[0] && strcmp(g->alpha_mode, "OPAQUE") != 0) {
      if (strcmp(g->alpha_mode, "MASK") && strcmp(g->alpha_mode, "BLEND"))
        return gltf_fail(c, IRIS_ERR_INVALID, el, "invalid alphaMode '%s'", g->alpha_mode);
      /* alpha = baseColorFactor.a x texture alpha x COLOR_0 alpha (glTF 2.0 section 3.9.4) */
      m->alpha_mode = strcmp(g->alpha_mode, "MASK") == 0 ? IRIS_ALPHA_MASK : IRIS_ALPHA_BLEND;
      m->alpha = (float)g->base_color[3];
      if (m->alpha_mode == IRIS_ALPHA_MASK) {
        if ((st = gltf_check_range(c, el, "alphaCutoff", g->alpha_cutoff, 0, HUGE_VAL))) return st;
        m->alpha_cutoff = (float)g->alpha_cutoff;
      }
    }
    if (g->unlit) {
      /* KHR_materials_unlit: the surface shows base colour x texture x vertex colour
       * as radiance and scatters nothing; every other property is ignored (the
       * extension). Stored as a black diffuse emitting the base colour through the
       * base colour texture; `unlit` multiplies in the vertex colours. The colour
       * texture stays for its alpha (MASK/BLEND), under a zero colour. */
      iris_material u = iris_material_default(IRIS_MATERIAL_DIFFUSE);
      u.name = m->name;
      u.unlit = true;
      for (int k = 0; k < 3; k++) u.emission[k] = m->color[k], u.color[k] = 0.0f;
      u.color_texture = m->color_texture;
      u.emission_texture = m->color_texture;
      u.emission_two_sided = m->emission_two_sided;
      u.double_sided = m->double_sided;
      u.alpha_mode = m->alpha_mode, u.alpha = m->alpha, u.alpha_cutoff = m->alpha_cutoff;
      *m = u;
      gltf_slot color_slot = slots[GLTF_SLOT_COLOR];
      for (int k = 0; k < GLTF_SLOT_COUNT; k++) slots[k].texture = -1;
      slots[GLTF_SLOT_COLOR] = slots[GLTF_SLOT_EMISSION] = color_slot;
      continue;
    }
    if (g->has_occlusion_texture) c->warned_occlusion = true;
  }
  return IRIS_OK;
}

/* Scene material for glTF material `gi` (-1: the glTF default material). */
iris_status gltf_resolve_material(gltf_ctx *c, int gi, int32_t *out) {
  if (gi < 0) {
    if (c->default_material < 0) {
      /* glTF 2.0 section 3.9.6: no material = base colour 1, metallic 1, roughness 1. */
      iris_material m = iris_material_default(IRIS_MATERIAL_GLTF);
      m.color[0] = m.color[1] = m.color[2] = 1.0f;
      m.metallic = 1.0f;
      m.roughness = 1.0f;
      m.emission_two_sided = false;
      m.name = iris_strdup("glTF default");
      c->default_material = iris_scene_add_material(c->scene, &m);
      if (c->default_material < 0) {
        free(m.name);
        return gltf_fail(c, IRIS_ERR_NOMEM, NULL, "out of memory");
      }
    }
    *out = c->default_material;
    return IRIS_OK;
  }
  if (c->material_map[gi] >= 0) {
    *out = c->material_map[gi];
    return IRIS_OK;
  }
  iris_material m = c->materials[gi];
  iris_status st;
  int32_t *fields[GLTF_SLOT_COUNT] = {&m.color_texture, &m.metallic_roughness_texture,
                                      &m.emission_texture, &m.normal_texture,
                                      &m.clearcoat_texture, &m.clearcoat_roughness_texture,
                                      &m.clearcoat_normal_texture, &m.sheen_color_texture,
                                      &m.sheen_roughness_texture, &m.transmission_texture,
                                      &m.specular_texture, &m.specular_color_texture, &m.anisotropy_texture};
  for (int k = 0; k < GLTF_SLOT_COUNT; k++) {
    if (!fields[k] || c->slots[gi][k].texture < 0) continue;
    int32_t id;
    if ((st = resolve_texture(c, &c->slots[gi][k], &id))) return st;
    *fields[k] = id >= 0 ? id : -1;
  }
  m.name = m.name ? iris_strdup(m.name) : NULL;
  int32_t id = iris_scene_add_material(c->scene, &m);
  if (id < 0) {
    free(m.name);
    return gltf_fail(c, IRIS_ERR_NOMEM, NULL, "out of memory");
  }
  *out = c->material_map[gi] = id;
  return IRIS_OK;
}
