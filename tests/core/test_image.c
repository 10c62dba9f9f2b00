/* core.image: EXR write -> read is bit-exact (channels in any order, odd
 * sizes, metadata); truncated or corrupted EXRs fail cleanly; PNG output
 * decodes to the sRGB encoding computed here independently; textures decode
 * like libpng decodes them; absurd sizes are refused. */
#include <math.h>
#include <png.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/fileio.h"
#include "core/image.h"
#include "core/rng.h"

static char dir[512];
static const char *assets;

static uint32_t bits(float f) {
  uint32_t u;
  memcpy(&u, &f, 4);
  return u;
}

/* Fills with a mix of ordinary, tiny, huge, signed-zero, infinite and NaN values. */
static void fill_special(iris_image *img, uint64_t seed) {
  size_t n = (size_t)img->width * img->height * img->channel_count;
  for (size_t i = 0; i < n; i++) {
    uint64_t h = iris_hash4(seed, i, 0, 0);
    float u = iris_u64_to_unit(h);
    float v;
    switch (h & 15) {
      case 0: v = -0.0f; break;
      case 1: v = INFINITY; break;
      case 2: v = -INFINITY; break;
      case 3: v = NAN; break;
      case 4: v = 1e-40f * u; break; /* denormal */
      case 5: v = 3e38f * u; break;
      default: v = (u - 0.3f) * 100.0f; break;
    }
    img->data[i] = v;
  }
}

static void test_exr_round_trip(int w, int h, int nc, const char *const *names, size_t meta_n) {
  iris_error err;
  iris_error_clear(&err);
  iris_image img;
  CHECK_OK(iris_image_create(&img, w, h, nc, names, &err), &err);
  if (err.status) return;
  fill_special(&img, (uint64_t)(w * 131 + h));
  iris_image_meta meta[4];
  memset(meta, 0, sizeof meta);
  strcpy(meta[0].key, "iris:spp");
  strcpy(meta[0].value, "1024");
  strcpy(meta[1].key, "iris:a_much_longer_attribute_name_than_31_chars");
  memset(meta[1].value, 'v', 1000);
  strcpy(meta[2].key, "iris:empty");
  strcpy(meta[3].key, "iris:utf8");
  strcpy(meta[3].value, "caf\xc3\xa9 \"quoted\" tab\there");

  char path[600];
  snprintf(path, sizeof path, "%s/rt_%dx%dx%d.exr", dir, w, h, nc);
  CHECK_OK(iris_exr_write(path, &img, meta, meta_n, &err), &err);
  CHECK_EQ_INT(iris_test_count_entries(dir, ".tmp-"), 0);

  iris_image back;
  iris_image_meta *rm = NULL;
  size_t rn = 0;
  iris_error_clear(&err);
  CHECK_OK(iris_exr_read(path, &back, &rm, &rn, &err), &err);
  if (err.status) {
    iris_image_destroy(&img);
    return;
  }
  CHECK_EQ_INT(back.width, w);
  CHECK_EQ_INT(back.height, h);
  CHECK_EQ_INT(back.channel_count, nc);
  for (int c = 0; c < nc; c++) {
    int bc = iris_image_channel(&back, names[c]);
    if (!iris_check_record(bc >= 0, __FILE__, __LINE__, "channel '%s' missing after round trip", names[c]))
      continue;
    size_t mismatches = 0;
    for (size_t p = 0; p < (size_t)w * h; p++)
      mismatches += bits(img.data[p * nc + c]) != bits(back.data[p * nc + bc]);
    iris_check_record(mismatches == 0, __FILE__, __LINE__, "%dx%d channel '%s': %zu values not bit-exact", w,
                      h, names[c], mismatches);
  }
  /* EXR stores channels sorted by name: the reader returns them in that order. */
  for (int c = 1; c < back.channel_count; c++)
    CHECK(strcmp(back.channel_names[c - 1], back.channel_names[c]) < 0);
  for (size_t i = 0; i < meta_n; i++) {
    const char *found = NULL;
    for (size_t k = 0; k < rn; k++)
      if (strcmp(rm[k].key, meta[i].key) == 0) found = rm[k].value;
    iris_check_record(found != NULL, __FILE__, __LINE__, "metadata '%s' missing", meta[i].key);
    if (found) CHECK_EQ_STR(found, meta[i].value);
  }
  free(rm);
  iris_image_destroy(&back);
  iris_image_destroy(&img);
}

static void test_exr_errors(void) {
  const char *names[] = {"R", "G", "B", "A"};
  iris_error err;
  iris_error_clear(&err);
  iris_image img;
  CHECK_OK(iris_image_create(&img, 64, 40, 4, names, &err), &err);
  for (size_t i = 0; i < 64 * 40 * 4; i++) img.data[i] = iris_u64_to_unit(iris_mix64(i)) * 4.0f;
  char path[600], bad[600];
  snprintf(path, sizeof path, "%s/good.exr", dir);
  snprintf(bad, sizeof bad, "%s/bad.exr", dir);
  CHECK_OK(iris_exr_write(path, &img, NULL, 0, &err), &err);
  iris_image_destroy(&img);

  char *data = NULL;
  size_t size = 0;
  CHECK_OK(iris_file_read(path, 0, &data, &size, &err), &err);
  if (!data) return;

  /* Truncations: every cut must be an error, never a crash or a partial image. */
  const size_t cuts[] = {0, 1, 4, 8, 20, 100, 300, size / 3, size / 2, size - 100, size - 1};
  for (size_t i = 0; i < sizeof cuts / sizeof *cuts; i++) {
    if (cuts[i] >= size) continue;
    CHECK_OK(iris_file_write_atomic(bad, data, cuts[i], &err), &err);
    iris_image r;
    iris_error_clear(&err);
    iris_status st = iris_exr_read(bad, &r, NULL, NULL, &err);
    iris_check_record(st != IRIS_OK, __FILE__, __LINE__, "EXR truncated to %zu of %zu bytes was accepted",
                      cuts[i], size);
    CHECK(r.data == NULL);
    CHECK_EQ_STR(err.file, bad);
    CHECK(err.message[0] != '\0');
  }

  /* Corruptions: flip bytes anywhere; reading may succeed (pixel bytes) but must not crash. */
  char *copy = malloc(size);
  int rejected = 0, trials = 0;
  for (uint64_t t = 0; t < 300 && copy; t++) {
    memcpy(copy, data, size);
    uint64_t h = iris_mix64(t + 1);
    size_t pos = t < 150 ? (size_t)(h % (size < 400 ? size : 400)) : (size_t)(h % size); /* header first */
    copy[pos] = (char)(copy[pos] ^ (char)(1 + (h >> 32) % 255));
    if (t % 3 == 0) copy[(pos + 7) % size] = (char)0xff;
    CHECK_OK(iris_file_write_atomic(bad, copy, size, &err), &err);
    iris_image r;
    iris_image_meta *m = NULL;
    size_t mn = 0;
    iris_error_clear(&err);
    iris_status st = iris_exr_read(bad, &r, &m, &mn, &err);
    trials++;
    if (st != IRIS_OK) {
      rejected++;
      CHECK(r.data == NULL && m == NULL);
    } else {
      CHECK(r.data != NULL && r.width > 0 && r.height > 0);
    }
    free(m);
    iris_image_destroy(&r);
  }
  printf("corrupted EXRs: %d of %d rejected, the rest read without error\n", rejected, trials);
  CHECK(rejected > 0);
  free(copy);

  /* Not an EXR at all, a missing file, a folder. */
  CHECK_OK(iris_file_write_atomic(bad, "P6\n1 1\n255\nabc", 14, &err), &err);
  iris_image r;
  iris_error_clear(&err);
  CHECK(iris_exr_read(bad, &r, NULL, NULL, &err) != IRIS_OK);
  char missing[600];
  snprintf(missing, sizeof missing, "%s/missing.exr", dir);
  iris_error_clear(&err);
  CHECK_EQ_INT(iris_exr_read(missing, &r, NULL, NULL, &err), IRIS_ERR_IO);
  CHECK_EQ_STR(err.file, missing);
  iris_error_clear(&err);
  CHECK(iris_exr_read(dir, &r, NULL, NULL, &err) != IRIS_OK);
  free(data);

  /* Writing into a missing folder fails and leaves nothing behind. */
  const char *one[] = {"Y"};
  iris_error_clear(&err);
  CHECK_OK(iris_image_create(&img, 3, 3, 1, one, &err), &err);
  char nodir[700];
  snprintf(nodir, sizeof nodir, "%s/nodir/x.exr", dir);
  iris_error_clear(&err);
  CHECK_EQ_INT(iris_exr_write(nodir, &img, NULL, 0, &err), IRIS_ERR_IO);
  /* A metadata key that clashes with a required attribute of another type fails atomically. */
  iris_image_meta clash = {"compression", "zip"};
  char cpath[600];
  snprintf(cpath, sizeof cpath, "%s/clash.exr", dir);
  iris_error_clear(&err);
  CHECK(iris_exr_write(cpath, &img, &clash, 1, &err) != IRIS_OK);
  CHECK(!iris_path_exists(cpath));
  CHECK_EQ_INT(iris_test_count_entries(dir, ".tmp-"), 0);
  iris_image_destroy(&img);

  /* Bad images are refused up front. */
  const char *dup[] = {"R", "R"};
  iris_error_clear(&err);
  CHECK_EQ_INT(iris_image_create(&img, 2, 2, 2, dup, &err), IRIS_ERR_INVALID);
  iris_error_clear(&err);
  CHECK_EQ_INT(iris_image_create(&img, 0, 2, 1, one, &err), IRIS_ERR_INVALID);
  iris_error_clear(&err);
  CHECK_EQ_INT(iris_image_create(&img, 2, 2, IRIS_IMAGE_MAX_CHANNELS + 1, NULL, &err), IRIS_ERR_INVALID);
}

/* Independent sRGB encoding (IEC 61966-2-1) in double precision. */
static int srgb8(double linear) {
  if (!(linear > 0)) return 0;
  double v = linear <= 0.0031308 ? 12.92 * linear : 1.055 * pow(linear, 1 / 2.4) - 0.055;
  if (v >= 1) return 255;
  return (int)floor(v * 255 + 0.5);
}

static void test_png(void) {
  const char *names[] = {"var.R", "R", "G", "B"};
  iris_error err;
  iris_error_clear(&err);
  iris_image img;
  CHECK_OK(iris_image_create(&img, 19, 5, 4, names, &err), &err);
  const float specials[] = {NAN, -1.0f, INFINITY, 0.0f, 1e-4f, 0.0031308f, 0.18f, 0.5f, 0.999f, 7.0f};
  for (int p = 0; p < 19 * 5; p++)
    for (int k = 0; k < 3; k++) {
      float v = p < 10 ? specials[p] : iris_u64_to_unit(iris_hash4(5, (uint64_t)p, (uint64_t)k, 0)) * 1.2f;
      img.data[p * 4 + 1 + k] = k == 1 && p < 10 ? v * 0.5f : v;
      img.data[p * 4] = 123.0f; /* not written */
    }
  const float exposures[] = {0.0f, 1.0f, -2.0f};
  for (int e = 0; e < 3; e++) {
    char path[600];
    snprintf(path, sizeof path, "%s/out%d.png", dir, e);
    iris_error_clear(&err);
    CHECK_OK(iris_png_write(path, &img, 1, exposures[e], &err), &err);
    iris_ldr_image ldr;
    CHECK_OK(iris_ldr_load_file(path, &ldr, &err), &err);
    if (!ldr.rgba) continue;
    CHECK_EQ_INT(ldr.width, 19);
    CHECK_EQ_INT(ldr.height, 5);
    int worst = 0;
    for (int p = 0; p < 19 * 5; p++) {
      for (int k = 0; k < 3; k++) {
        double lin = (double)img.data[p * 4 + 1 + k] * pow(2.0, exposures[e]);
        int d = abs(ldr.rgba[p * 4 + k] - srgb8(lin));
        if (d > worst) worst = d;
      }
      CHECK_EQ_INT(ldr.rgba[p * 4 + 3], 255);
    }
    iris_check_record(worst <= 1, __FILE__, __LINE__, "PNG exposure %g: worst 8-bit error %d", exposures[e], worst);
    CHECK_EQ_INT(ldr.rgba[0], 0);   /* NaN */
    CHECK_EQ_INT(ldr.rgba[4], 0);   /* negative */
    CHECK_EQ_INT(ldr.rgba[8], 255); /* +inf */
    iris_ldr_destroy(&ldr);
  }
  iris_error_clear(&err);
  CHECK_EQ_INT(iris_png_write("/nonexistent-dir/x.png", &img, 1, 0, &err), IRIS_ERR_IO);
  iris_error_clear(&err);
  CHECK_EQ_INT(iris_png_write("x.png", &img, 2, 0, &err), IRIS_ERR_INVALID); /* c0+2 out of range */
  CHECK_EQ_INT(iris_test_count_entries(dir, ".tmp-"), 0);
  iris_image_destroy(&img);
}

static void test_srgb(void) {
  /* Reference values of the piecewise curve. */
  CHECK_NEAR(iris_linear_to_srgb(0.0f), 0.0, 0);
  CHECK_NEAR(iris_linear_to_srgb(1.0f), 1.0, 1e-6);
  CHECK_NEAR(iris_linear_to_srgb(0.5f), 0.735356983, 1e-6);
  CHECK_NEAR(iris_linear_to_srgb(0.0031308f), 0.04045, 1e-6);
  CHECK_NEAR(iris_linear_to_srgb(0.001f), 0.01292, 1e-7);
  CHECK_NEAR(iris_srgb_to_linear(0.5f), 0.214041140, 1e-6);
  CHECK_NEAR(iris_srgb_to_linear(0.04045f), 0.0031308, 1e-6);
  CHECK_NEAR(iris_srgb_to_linear(1.0f), 1.0, 1e-6);
  float worst = 0;
  for (int i = 0; i <= 1000; i++) {
    float v = i / 1000.0f;
    worst = fmaxf(worst, fabsf(iris_linear_to_srgb(iris_srgb_to_linear(v)) - v));
  }
  CHECK_NEAR(worst, 0, 1e-5);
}

/* Decodes a PNG with libpng's simplified API into RGBA: the independent reference. */
static uint8_t *libpng_rgba(const char *path, int *w, int *h) {
  png_image im;
  memset(&im, 0, sizeof im);
  im.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&im, path)) return NULL;
  im.format = PNG_FORMAT_RGBA;
  uint8_t *buf = malloc(PNG_IMAGE_SIZE(im));
  if (!buf || !png_image_finish_read(&im, NULL, buf, 0, NULL)) {
    free(buf);
    png_image_free(&im);
    return NULL;
  }
  *w = (int)im.width;
  *h = (int)im.height;
  return buf;
}

static void test_textures(void) {
  const char *pngs[] = {"gltf/BoxTextured/glTF/CesiumLogoFlat.png", "obj/spot/spot_texture.png",
                        "gltf/EmissiveStrengthTest/glTF/PlainGrid.png"};
  iris_error err;
  for (int i = 0; i < 3; i++) {
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", assets, pngs[i]);
    iris_ldr_image img;
    iris_error_clear(&err);
    CHECK_OK(iris_ldr_load_file(path, &img, &err), &err);
    int w = 0, h = 0;
    uint8_t *ref = libpng_rgba(path, &w, &h);
    CHECK(ref != NULL);
    if (img.rgba && ref) {
      CHECK_EQ_INT(img.width, w);
      CHECK_EQ_INT(img.height, h);
      size_t diff = 0;
      for (size_t k = 0; k < (size_t)w * h * 4; k++) diff += img.rgba[k] != ref[k];
      iris_check_record(diff == 0, __FILE__, __LINE__, "%s: %zu bytes differ from libpng", pngs[i], diff);
    }
    free(ref);
    iris_ldr_destroy(&img);
  }
  char jpg[1200];
  snprintf(jpg, sizeof jpg, "%s/gltf/CesiumMilkTruck/glTF/CesiumMilkTruck.jpg", assets);
  iris_ldr_image img;
  iris_error_clear(&err);
  CHECK_OK(iris_ldr_load_file(jpg, &img, &err), &err);
  CHECK_EQ_INT(img.width, 2048); /* progressive JPEG, 2048x2048 per its header */
  CHECK_EQ_INT(img.height, 2048);
  if (img.rgba) CHECK_EQ_INT(img.rgba[3], 255);
  iris_ldr_destroy(&img);

  /* Errors name the file or the given description. */
  char missing[600];
  snprintf(missing, sizeof missing, "%s/missing.png", dir);
  iris_error_clear(&err);
  CHECK_EQ_INT(iris_ldr_load_file(missing, &img, &err), IRIS_ERR_IO);
  CHECK_EQ_STR(err.file, missing);
  iris_error_clear(&err);
  CHECK_EQ_INT(iris_ldr_load_memory("not an image at all", 19, "textures[3]", &img, &err), IRIS_ERR_PARSE);
  CHECK_EQ_STR(err.file, "textures[3]");
  CHECK(img.rgba == NULL);
  iris_error_clear(&err);
  CHECK(iris_ldr_load_memory("", 0, "empty", &img, &err) != IRIS_OK);

  /* fuzz_texture's reproducer: a 16x16 PNG whose last bytes are a second
   * IDAT's header declaring 0x4945003b bytes (no data, no CRC). stb_image
   * would grow its buffer to 2 GB; refused by the chunk walk instead. */
  {
    static const uint8_t cut[] = {
        0x89, 0x50, 0x4e, 0x47, 0xd,  0xa,  0x1a, 0xa,  0x0,  0x0,  0x0,  0xd,  0x49, 0x48, 0x44, 0x52, 0x0,  0x0,
        0x0,  0x10, 0x0,  0x0,  0x0,  0x10, 0x8,  0x0,  0x0,  0x0,  0x0,  0x3a, 0x98, 0xa0, 0xbd, 0x0,  0x0,  0x0,
        0x3b, 0x49, 0x44, 0x41, 0x54, 0x78, 0x5e, 0x63, 0x64, 0x50, 0x45, 0x5,  0x8c, 0x81, 0xe8, 0x2,  0x8b, 0xd0,
        0x5,  0x3e, 0xa3, 0xb,  0xb8, 0xa0, 0xb,  0x4c, 0x45, 0x17, 0x78, 0x86, 0x0,  0x0,  0x0,  0x0,  0x0,  0x0,
        0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,
        0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,  0x0,
        0x0,  0x0,  0x49, 0x45, 0x0,  0x3b, 0x49, 0x44, 0x41, 0x54, 0x82};
    iris_error_clear(&err);
    CHECK_EQ_INT(iris_ldr_load_memory(cut, sizeof cut, "cut.png", &img, &err), IRIS_ERR_PARSE);
    CHECK(img.rgba == NULL);
    iris_check_record(strstr(err.message, "PNG chunk") != NULL, __FILE__, __LINE__, "message: %s", err.message);
    /* a piece of a chunk header after the last chunk */
    static const uint8_t stub[] = {0x89, 0x50, 0x4e, 0x47, 0xd, 0xa, 0x1a, 0xa, 0x0, 0x0, 0x0};
    iris_error_clear(&err);
    CHECK_EQ_INT(iris_ldr_load_memory(stub, sizeof stub, "stub.png", &img, &err), IRIS_ERR_PARSE);
  }

  /* A PNG header declaring absurd sizes is refused before decoding. */
  const uint32_t sizes[][2] = {{100000, 10}, {60000, 60000}};
  for (int i = 0; i < 2; i++) {
    uint8_t png[33] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R'};
    for (int b = 0; b < 4; b++) {
      png[16 + b] = (uint8_t)(sizes[i][0] >> (24 - 8 * b));
      png[20 + b] = (uint8_t)(sizes[i][1] >> (24 - 8 * b));
    }
    png[24] = 8;
    png[25] = 6;
    iris_error_clear(&err);
    iris_status st = iris_ldr_load_memory(png, sizeof png, "huge.png", &img, &err);
    iris_check_record(st != IRIS_OK, __FILE__, __LINE__, "%ux%u PNG accepted", sizes[i][0], sizes[i][1]);
    CHECK(img.rgba == NULL);
  }
}

/* A JPEG whose header declares far more pixels than its bytes can hold (a
 * real one with its size patched to 16384 x 16384 and its scan cut short) is
 * refused before decoding; stb_image would decode it all as if zeros followed. */
static void test_jpeg_absurd_size(void) {
  char path[1024];
  snprintf(path, sizeof path, "%s/gltf/CesiumMilkTruck/glTF/CesiumMilkTruck.jpg", assets);
  char *data = NULL;
  size_t size = 0;
  iris_error err;
  CHECK_OK(iris_file_read(path, (size_t)1 << 26, &data, &size, &err), &err);
  if (!data) return;
  size_t i = 2, sof = 0, cut = 0;
  while (i + 4 <= size && (unsigned char)data[i] == 0xFF) {
    const unsigned m = (unsigned char)data[i + 1];
    const size_t len = (size_t)(unsigned char)data[i + 2] << 8 | (unsigned char)data[i + 3];
    if (m >= 0xC0 && m <= 0xC2) sof = i;
    if (m == 0xDA) {
      cut = i + 2 + len + 512;
      break;
    }
    i += 2 + len;
  }
  CHECK(sof > 0 && cut > 0 && cut < size);
  if (sof > 0 && cut > 0 && cut < size) {
    iris_ldr_image ldr;
    CHECK_OK(iris_ldr_load_memory(data, size, "CesiumMilkTruck.jpg", &ldr, &err), &err);
    if (ldr.rgba) iris_ldr_destroy(&ldr);
    data[sof + 5] = 0x40, data[sof + 6] = 0, data[sof + 7] = 0x40, data[sof + 8] = 0;
    const iris_status st = iris_ldr_load_memory(data, cut, "huge.jpg", &ldr, &err);
    CHECK_EQ_INT(st, IRIS_ERR_INVALID);
    if (st == IRIS_OK) iris_ldr_destroy(&ldr);
  }
  free(data);
}

int main(int argc, char **argv) {
  assets = argc > 1 ? argv[1] : "../shared/assets";
  if (iris_test_tmpdir(dir, sizeof dir, "image") != 0) {
    fprintf(stderr, "cannot create a temporary directory\n");
    return 1;
  }
  const char *five[] = {"R", "G", "B", "A", "var.R"};
  const char *shuffled[] = {"var.B", "Z", "albedo.G", "B", "A", "R", "G", "N.x"};
  test_exr_round_trip(1, 1, 1, five, 4);
  test_exr_round_trip(37, 23, 5, five, 4);
  test_exr_round_trip(13, 11, 4, five, 1); /* RGBA: the layout with special-cased (un)packers */
  test_exr_round_trip(7, 5, 3, five, 1);
  test_exr_round_trip(64, 17, 8, shuffled, 2); /* 17 rows: a partial 16-line ZIP chunk */
  test_exr_round_trip(301, 2, 4, shuffled, 0);
  test_exr_round_trip(3, 200, 2, shuffled + 6, 1);
  test_exr_errors();
  test_png();
  test_srgb();
  test_textures();
  test_jpeg_absurd_size();
  iris_test_rmtree(dir);
  return TEST_SUMMARY();
}
