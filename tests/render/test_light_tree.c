/* The light tree (renderer/light_tree.h, docs/rendering.md "Light tree"):
 *  - at many shading points (inside the lights' bounds, far away, on the back
 *    of one-sided emitters, on a grazing plane, with and without a normal) the
 *    light choice follows its pmf (chi-square over the lights, cells of
 *    expected count < 5 pooled, Sidak-corrected), the pmf sums to one over the
 *    lights less the probability of a dead end (a node whose two children
 *    both have importance 0: the sampler returns nothing, and the chi-square
 *    counts that outcome as a cell of its own), and every
 *    sample's pmf equals iris_light_tree_pmf of its light bit for bit;
 *  - zero-power lights are never chosen and have pmf 0; one light; 4096
 *    identical lights at one point; lights behind every receiver; lights
 *    beside infinite ones;
 *  - the descent's vectorised importance of each wide node's lanes equals
 *    the scalar importance of their binary nodes;
 *  - the build is deterministic; through iris_lights, the entries' pmfs of a
 *    built-in scene sum to one within the dead ends' share (< 5%);
 *  - renders: mis with the tree and with the power sampler, and nee with the
 *    tree, agree within statistical error (cornell-box, veach-mis, office), a tree
 *    render is the same for 1 and 2 threads, and on cornell-box (one leaf: no
 *    tree kept) the tree setting renders the power sampler's image bit for bit. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "render_run.h"
#include "chi2.h"
#include "film_stats.h"
#include "renderer/light_tree.h"
#include "renderer/lights.h"
#include "renderer/render.h"
#include "scenes/builtin.h"

#define N_SETS 5
#define N_POINTS 8
#define N_SAMPLES 200000
static const int N_CHI2_TESTS = N_SETS * N_POINTS * 2;

static double uniform(uint64_t *s) { return chi2_uniform(s); }

static iris_light_bounds triangle_bounds(iris_vec3 a, iris_vec3 b, iris_vec3 c, float phi, bool two_sided) {
  iris_light_bounds l;
  memset(&l, 0, sizeof l);
  l.lo = iris_v3(fminf(a.x, fminf(b.x, c.x)), fminf(a.y, fminf(b.y, c.y)), fminf(a.z, fminf(b.z, c.z)));
  l.hi = iris_v3(fmaxf(a.x, fmaxf(b.x, c.x)), fmaxf(a.y, fmaxf(b.y, c.y)), fmaxf(a.z, fmaxf(b.z, c.z)));
  l.w = iris_normalize(iris_cross(iris_sub(b, a), iris_sub(c, a)));
  l.cos_o = 1.0f;
  l.cos_e = 0.0f;
  l.phi = phi;
  l.two_sided = two_sided;
  l.cluster = UINT32_MAX;
  return l;
}
static iris_light_bounds point_bounds(iris_vec3 p, float phi) {
  iris_light_bounds l;
  memset(&l, 0, sizeof l);
  l.lo = l.hi = p;
  l.w = iris_v3(0, 0, 1);
  l.cos_o = -1.0f;
  l.phi = phi;
  l.cluster = UINT32_MAX;
  return l;
}

/* Light sets: 0 mixed random triangles (some two-sided, some of zero power,
 * clusters) + points + spots; 1 one light; 2 4096 identical points at one
 * place; 3 ceiling lamps facing down (-z) at z = 3; 4 set 3 plus a sky and a
 * distant light. */
static size_t make_set(int set, iris_light_bounds *l) {
  uint64_t rs = 12345 + (uint64_t)set;
  size_t n = 0;
  switch (set) {
    case 0:
      for (int i = 0; i < 300; i++) {
        iris_vec3 a = iris_v3((float)(4 * uniform(&rs) - 2), (float)(4 * uniform(&rs) - 2), (float)(4 * uniform(&rs) - 2));
        iris_vec3 b = iris_add(a, iris_v3((float)(0.3 * uniform(&rs)), (float)(0.3 * uniform(&rs)), (float)(0.3 * uniform(&rs) - 0.15)));
        iris_vec3 c = iris_add(a, iris_v3((float)(0.3 * uniform(&rs) - 0.15), (float)(0.3 * uniform(&rs)), (float)(0.3 * uniform(&rs))));
        float phi = i % 17 == 0 ? 0.0f : (float)(0.01 + 10 * uniform(&rs) * uniform(&rs));
        l[n] = triangle_bounds(a, b, c, phi, i % 5 == 0);
        if (i % 3 == 0) l[n].cluster = (uint32_t)(i / 30); /* may share leaves */
        n++;
      }
      for (int i = 0; i < 20; i++) {
        l[n++] = point_bounds(iris_v3((float)(4 * uniform(&rs) - 2), (float)(4 * uniform(&rs) - 2), (float)(4 * uniform(&rs) - 2)),
                              i == 7 ? 0.0f : (float)(1 + 5 * uniform(&rs)));
      }
      for (int i = 0; i < 10; i++) { /* spots pointing down, 30 degrees */
        l[n] = point_bounds(iris_v3((float)(4 * uniform(&rs) - 2), (float)(4 * uniform(&rs) - 2), 2.0f), 3.0f);
        l[n].w = iris_v3(0, 0, -1);
        l[n].cos_o = 1.0f;
        l[n].cos_e = cosf(0.5f);
        n++;
      }
      break;
    case 1:
      l[n++] = triangle_bounds(iris_v3(0, 0, 1), iris_v3(0, 1, 1), iris_v3(1, 0, 1), 2.0f, false); /* faces -z */
      break;
    case 2:
      for (int i = 0; i < 4096; i++) l[n++] = point_bounds(iris_v3(0.5f, 0.5f, 0.5f), 1.0f);
      break;
    case 3:
    case 4:
      for (int i = 0; i < 20; i++)
        for (int j = 0; j < 20; j++) {
          float x = -10.0f + (float)i, y = -10.0f + (float)j;
          float phi = (i * 7 + j * 3) % 11 == 0 ? 0.0f : (float)(1 + (i + j) % 4);
          l[n++] = triangle_bounds(iris_v3(x, y, 3), iris_v3(x, y + 0.2f, 3), iris_v3(x + 0.2f, y, 3), phi, false);
          l[n - 1].cluster = (uint32_t)(i * 20 + j);
        }
      if (set == 4) {
        iris_light_bounds sky;
        memset(&sky, 0, sizeof sky);
        sky.infinite = true;
        sky.phi = 2.0f;
        sky.cluster = UINT32_MAX;
        l[n++] = sky;
        sky.phi = 0.5f;
        l[n++] = sky;
        sky.phi = 0.0f;
        l[n++] = sky;
      }
      break;
    default: break;
  }
  return n;
}

/* Shading points: inside the bounds, far away, above and below the ceiling
 * lamps (their backs), a grazing plane; normals given or not (see main). */
static void make_point(int k, iris_vec3 *p, iris_vec3 *n) {
  static const float P[N_POINTS][6] = {
      {0.1f, 0.2f, 0.3f, 0, 0, 1},        /* inside */
      {0.5f, 0.5f, 0.5f, 0, 1, 0},        /* at the identical points */
      {200.0f, -150.0f, 80.0f, -1, 0, 0}, /* far away */
      {0.0f, 0.0f, 5.0f, 0, 0, 1},        /* above the lamps: behind them, facing up */
      {0.0f, 0.0f, 3.0f, 0, 0, -1},       /* in the lamps' plane */
      {3.0f, 1.0f, 0.0f, 0, 0, 1},        /* floor under the lamps */
      {-12.0f, 0.0f, 2.9f, 0, 0.0871557f, 0.9961947f}, /* grazing: 85 degrees from the lamps */
      {1.0f, -1.0f, -0.5f, 0.577f, 0.577f, 0.577f}};
  *p = iris_v3(P[k][0], P[k][1], P[k][2]);
  *n = iris_normalize(iris_v3(P[k][3], P[k][4], P[k][5]));
}

/* Chi-square of the choice against the pmf; also the bit-for-bit check of
 * every sample and the normalisation. */
static void check_point(const iris_light_tree *t, const iris_light_bounds *l, size_t n, int set, iris_vec3 p,
                        iris_vec3 nrm, double alpha_total) {
  double *pmf = calloc(n, sizeof *pmf);
  size_t *hits = calloc(n, sizeof *hits);
  double sum = 0.0;
  for (size_t i = 0; i < n; i++) {
    pmf[i] = iris_light_tree_pmf(t, p, nrm, (uint32_t)i);
    sum += pmf[i];
    if (!(l[i].phi > 0.0f)) CHECK(pmf[i] == 0.0);
    CHECK(pmf[i] >= 0.0 && pmf[i] <= 1.0);
  }
  uint64_t rs = 99 + (uint64_t)set * 1000;
  size_t got = 0, mismatch = 0, zero_chosen = 0;
  for (int s = 0; s < N_SAMPLES; s++) {
    uint32_t light;
    float q;
    if (!iris_light_tree_sample(t, p, nrm, (float)uniform(&rs), &light, &q)) continue;
    got++;
    if (light >= n) {
      mismatch++;
      continue;
    }
    if (q != iris_light_tree_pmf(t, p, nrm, light)) mismatch++;
    if (!(l[light].phi > 0.0f) || !(pmf[light] > 0.0)) zero_chosen++;
    hits[light]++;
  }
  iris_check_record(mismatch == 0, __FILE__, __LINE__, "set %d point (%g,%g,%g): %zu samples whose pmf differs from the pmf function",
                    set, p.x, p.y, p.z, mismatch);
  iris_check_record(zero_chosen == 0, __FILE__, __LINE__, "set %d: %zu samples of lights with pmf or power 0", set, zero_chosen);
  /* The pmfs sum to one less the probability of "nothing" (a descent that
   * meets two children of importance 0: the sampler fails, consistently). */
  iris_check_record(sum <= 1.0 + 1e-5, __FILE__, __LINE__, "set %d point (%g,%g,%g): pmfs sum to %.7f", set, p.x, p.y,
                    p.z, sum);
  if (got == 0) {
    iris_check_record(sum == 0.0, __FILE__, __LINE__, "set %d point (%g,%g,%g): nothing sampled but the pmfs sum to %g",
                      set, p.x, p.y, p.z, sum);
  } else {
    printf("set %d point (%g,%g,%g) n (%g,%g,%g): pmfs sum to %.6f\n", set, p.x, p.y, p.z, nrm.x, nrm.y, nrm.z, sum);
    /* Pearson over the lights and "nothing", pooling cells of expected count < 5 */
    double chi;
    int dof;
    double pv = chi2_discrete(pmf, hits, n, N_SAMPLES, got, &chi, &dof);
    double sig = 1.0 - pow(1.0 - alpha_total, 1.0 / N_CHI2_TESTS);
    iris_check_record(pv > sig, __FILE__, __LINE__, "set %d point (%g,%g,%g) n (%g,%g,%g): chi2 %.1f dof %d p %.3g < %.3g",
                      set, p.x, p.y, p.z, nrm.x, nrm.y, nrm.z, chi, dof, pv, sig);
  }
  free(pmf);
  free(hits);
}

/* The descent's vectorised importance of every lane of every wide node
 * equals the scalar importance of the lane's binary node, at the test points
 * and at random ones (with and without a normal), and the wide nodes cover
 * the binary tree: every lane is a child or grandchild of its node's origin. */
static void check_wide(const iris_light_tree *t, int set) {
  if (!t->wide) return;
  uint64_t rs = 777 + (uint64_t)set;
  size_t bad = 0, zero_mismatch = 0, lanes = 0;
  for (int q = 0; q < 200; q++) {
    iris_vec3 p, n;
    if (q < N_POINTS) {
      make_point(q, &p, &n);
    } else {
      p = iris_v3((float)(30 * uniform(&rs) - 15), (float)(30 * uniform(&rs) - 15), (float)(8 * uniform(&rs) - 2));
      n = iris_normalize(iris_v3((float)(uniform(&rs) - 0.5), (float)(uniform(&rs) - 0.5), (float)(uniform(&rs) - 0.5)));
    }
    if (q % 2) n = iris_v3(0, 0, 0);
    for (size_t wi = 0; wi < t->wide_count; wi++) {
      float got[IRIS_LIGHT_WIDE];
      iris_light_tree_wide_importance(t, wi, p, n, got);
      for (int k = 0; k < IRIS_LIGHT_WIDE; k++) {
        const iris_light_tree_wide *w = &t->wide[wi];
        if (!(w->phi[k] > 0.0f)) {
          bad += got[k] != 0.0f;
          continue;
        }
        lanes++;
        float want = iris_light_tree_node_importance(&t->nodes[w->node[k]], p, n);
        if ((want > 0.0f) != (got[k] > 0.0f)) zero_mismatch++;
        else if (fabsf(want - got[k]) > 1e-5f * fmaxf(want, got[k])) bad++;
      }
    }
  }
  iris_check_record(bad == 0 && zero_mismatch == 0 && lanes > 0, __FILE__, __LINE__,
                    "set %d: %zu of %zu wide lanes' importances differ from the node's, %zu only in being 0", set, bad,
                    lanes, zero_mismatch);
}

static bool render(const iris_scene *s, iris_method m, iris_light_sampler ls, int threads, int w, int h, int spp,
                   uint64_t seed, iris_render_result *r) {
  return iris_test_render_light(s, m, ls, threads, w, h, spp, seed, NULL, r);
}

int main(void) {
  iris_light_bounds *l = calloc(8192, sizeof *l);
  for (int set = 0; set < N_SETS; set++) {
    size_t n = make_set(set, l);
    iris_light_tree t, t2;
    iris_error err;
    if (!CHECK(iris_light_tree_build(l, n, 0.5f, &t, &err) == IRIS_OK)) continue;
    /* deterministic build */
    if (CHECK(iris_light_tree_build(l, n, 0.5f, &t2, &err) == IRIS_OK)) {
      CHECK(t.node_count == t2.node_count &&
            memcmp(t.nodes, t2.nodes, t.node_count * sizeof *t.nodes) == 0 &&
            memcmp(t.bits, t2.bits, n * sizeof *t.bits) == 0);
      CHECK(t.wide_count == t2.wide_count &&
            (!t.wide || memcmp(t.wide, t2.wide, t.wide_count * sizeof *t.wide) == 0));
      iris_light_tree_destroy(&t2);
    }
    check_wide(&t, set);
    for (int k = 0; k < N_POINTS; k++)
      for (int with_n = 0; with_n < 2; with_n++) {
        iris_vec3 p, nrm;
        make_point(k, &p, &nrm);
        if (!with_n) nrm = iris_v3(0, 0, 0);
        check_point(&t, l, n, set, p, nrm, 0.01);
      }
    if (set == 1) { /* one light facing -z: the point below gets it, the one above nothing */
      CHECK(iris_light_tree_pmf(&t, iris_v3(0.2f, 0.2f, 0), iris_v3(0, 0, 1), 0) == 1.0f);
      CHECK(iris_light_tree_pmf(&t, iris_v3(0.2f, 0.2f, 2), iris_v3(0, 0, 0), 0) == 0.0f);
    }
    if (set == 3) { /* a light behind every receiver: above the lamps, or facing away */
      uint32_t light;
      float q;
      CHECK(!iris_light_tree_sample(&t, iris_v3(1, 1, 4), iris_v3(0, 0, 1), 0.5f, &light, &q));
      CHECK(!iris_light_tree_sample(&t, iris_v3(1, 1, 0), iris_v3(0, 0, -1), 0.5f, &light, &q));
    }
    if (set == 2) CHECK_NEAR(iris_light_tree_pmf(&t, iris_v3(3, 0, 0), iris_v3(0, 0, 0), 17), 1.0 / 4096, 1e-9);
    iris_light_tree_destroy(&t);
  }
  free(l);

  /* Through iris_lights on built-in scenes: the entries' pmfs sum to one. */
  {
    const char *names[3] = {"cornell-box", "veach-mis", "office"};
    for (int c = 0; c < 3; c++) {
      iris_scene *s = NULL;
      iris_error err;
      iris_accel *accel = NULL;
      iris_textures tex;
      iris_lights lights;
      memset(&tex, 0, sizeof tex);
      if (!CHECK(iris_builtin_create(names[c], &s, &err) == IRIS_OK)) continue;
      CHECK_OK(iris_accel_build(s, &accel, &err), &err);
      CHECK_OK(iris_lights_build(s, accel, &tex, &lights, &err), &err);
      CHECK_OK(iris_lights_set_sampler(&lights, IRIS_LIGHT_SAMPLER_TREE, &err), &err);
      CHECK((lights.tree != NULL) == (c != 0)); /* Cornell's light is one leaf: no tree kept */
      if (lights.tree) {
        size_t leaves = 0;
        for (size_t i = 0; i < lights.tree->node_count; i++) leaves += lights.tree->nodes[i].flags & IRIS_LIGHT_NODE_LEAF;
        printf("%s: %zu lights, %zu nodes, %zu leaves, %zu wide nodes of %zu bytes\n", names[c], lights.count,
               lights.tree->node_count, leaves, lights.tree->wide_count, sizeof *lights.tree->wide);
      }
      iris_vec3 refs[3] = {iris_v3(0, 0.5f, 0.5f), iris_v3(0.1f, -0.3f, 1.2f), iris_v3(3, 2, 1)};
      for (int i = 0; i < 3; i++) {
        double sum = 0.0;
        for (size_t e = 0; e < lights.count; e++)
          sum += iris_lights_select_pmf_at(&lights, refs[i], iris_v3(0, 0, 0), (uint32_t)e);
        /* one less the dead ends' probability (see check_point), which are rare here */
        iris_check_record(sum <= 1.0 + 1e-5 && sum > 0.95, __FILE__, __LINE__, "%s: entry pmfs sum to %.7f", names[c], sum);
      }
      iris_lights_destroy(&lights);
      iris_accel_destroy(accel);
      iris_scene_destroy(s);
    }
  }

  /* Renders: mis@tree vs mis@power vs nee@tree; 1 vs 2 threads. */
  {
    const struct {
      const char *name;
      int w, h, spp;
    } cases[3] = {{"cornell-box", 24, 24, 128}, {"veach-mis", 32, 24, 256}, {"office", 24, 15, 96}};
    int n_tests = 3 * 3 * 3 * 10;
    double z_max = z_for_alpha(1e-3 / n_tests);
    for (int c = 0; c < 3; c++) {
      iris_scene *s = NULL;
      iris_error err;
      if (!CHECK(iris_builtin_create(cases[c].name, &s, &err) == IRIS_OK)) continue;
      iris_render_result r[3], r1;
      bool ok[3];
      ok[0] = CHECK(render(s, IRIS_METHOD_MIS, IRIS_LIGHT_SAMPLER_TREE, 2, cases[c].w, cases[c].h, cases[c].spp, 1, &r[0]));
      ok[1] = CHECK(render(s, IRIS_METHOD_MIS, IRIS_LIGHT_SAMPLER_POWER, 2, cases[c].w, cases[c].h, cases[c].spp, 2, &r[1]));
      ok[2] = CHECK(render(s, IRIS_METHOD_NEE, IRIS_LIGHT_SAMPLER_TREE, 2, cases[c].w, cases[c].h, cases[c].spp, 3, &r[2]));
      if (ok[0] && CHECK(render(s, IRIS_METHOD_MIS, IRIS_LIGHT_SAMPLER_TREE, 1, cases[c].w, cases[c].h, cases[c].spp, 1, &r1))) {
        size_t np = (size_t)r1.film.width * (size_t)r1.film.height;
        iris_check_record(memcmp(r1.film.sum, r[0].film.sum, 3 * np * sizeof(double)) == 0, __FILE__, __LINE__,
                          "%s: the tree render differs between 1 and 2 threads", cases[c].name);
        CHECK(r1.light_sampler == IRIS_LIGHT_SAMPLER_TREE);
        iris_render_result_destroy(&r1);
      }
      if (c == 0 && ok[1]) { /* one leaf: no tree is kept, the image is the power sampler's bit for bit */
        iris_render_result rt;
        if (CHECK(render(s, IRIS_METHOD_MIS, IRIS_LIGHT_SAMPLER_TREE, 2, cases[c].w, cases[c].h, cases[c].spp, 2, &rt))) {
          size_t np = (size_t)rt.film.width * (size_t)rt.film.height;
          iris_check_record(memcmp(rt.film.sum, r[1].film.sum, 3 * np * sizeof(double)) == 0, __FILE__, __LINE__,
                            "cornell-box: tree and power renders differ although the tree is one leaf");
          iris_render_result_destroy(&rt);
        }
      }
      for (int a = 0; a < 3; a++)
        for (int b = a + 1; b < 3; b++) {
          if (!ok[a] || !ok[b]) continue;
          /* the image, and 3 x 3 blocks (veach nee: the image only, render.unbiased says why) */
          int grid = (c == 1 && (a == 2 || b == 2)) ? 0 : 3;
          char pair[120];
          snprintf(pair, sizeof pair, "%s: runs %d vs %d", cases[c].name, a, b);
          double worst = iris_test_z_compare(&r[a].film, &r[b].film, grid, grid, z_max, z_max, pair);
          printf("%s: run %d vs %d (mis@tree, mis@power, nee@tree): worst |z| = %.2f\n", cases[c].name, a, b, worst);
        }
      for (int m = 0; m < 3; m++)
        if (ok[m]) {
          CHECK_EQ_INT(r[m].stats.nan_count, 0);
          iris_render_result_destroy(&r[m]);
        }
      iris_scene_destroy(s);
    }
  }
  return iris_check_summary("render.light_tree");
}
