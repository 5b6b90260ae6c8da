/* Case files: loading, defaults, getters, resolved text, and the exact text of
 * every kind of error message (the format users rely on:
 * "FILE:LINE:COL: key.path: message"). Uses a test-only solver section with
 * lists, variants and vectors so it does not depend on the real solvers. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/schema.h"
#include "solvers/solver.h"
#include "px_test.h"

static struct px_context *ctx;
static struct px_case_root_storage storage;
static const struct px_schema *root;

/* ------------------------------------------------------------------------ */
/* The test solver section "demo" (and an empty-ish "other") */

static const struct px_schema naca_keys[] = {
    PX_KEY_STRING("digits", "NACA 4-digit designation", PX_REQUIRED),
    PX_KEY_REAL("chord", "chord length [m]", PX_GT(0), PX_DEFAULT("1")),
    PX_KEY_REAL("angle", "angle of attack [deg]", PX_IN(-90, 90), PX_DEFAULT("0")),
    PX_KEY_INT("panels", "number of panels", PX_GE(8), PX_DEFAULT("64")), PX_KEY_END};
static const struct px_schema circle_keys[] = {
    PX_KEY_REAL("radius", "radius [m]", PX_GT(0), PX_REQUIRED),
    PX_KEY_VECTOR("center", "centre [m]", PX_LEN(2, 2), PX_DEFAULT("[0, 0]")), PX_KEY_END};
static const struct px_schema ellipse_keys[] = {
    PX_KEY_REAL("a", "semi-axis along x [m]", PX_GT(0), PX_REQUIRED),
    PX_KEY_REAL("b", "semi-axis along y [m]", PX_GT(0), PX_REQUIRED), PX_KEY_END};
static const struct px_schema body_types[] = {
    PX_TYPE("circle", circle_keys, "a circle"), PX_TYPE("ellipse", ellipse_keys, "an ellipse"),
    PX_TYPE("naca", naca_keys, "a NACA 4-digit airfoil"), PX_KEY_END};
static const struct px_schema body = PX_KEY_VARIANT("body", body_types, "a solid body");
static const struct px_schema probe = PX_KEY_VECTOR("probe", "probe point [m]", PX_LEN(2, 2));

static enum px_status window_check(struct px_case *c, const char *path) {
  char a[128], b[128];
  double lo, hi;
  PX_TRY(px_case_get_real(c, px_case_path_join(a, sizeof a, path, "lo"), &lo));
  PX_TRY(px_case_get_real(c, px_case_path_join(b, sizeof b, path, "hi"), &hi));
  if (!(lo < hi)) return px_case_fail(c, path, "lo must be below hi (got lo %g, hi %g)", lo, hi);
  return PX_STATUS_OK;
}
static const struct px_schema window_keys[] = {
    PX_KEY_REAL("lo", "window start [s]", PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("hi", "window end [s]", PX_GE(0), PX_DEFAULT("1")), PX_KEY_END};

static const struct px_schema uniform_keys[] = {
    PX_KEY_REAL("speed", "inflow speed [m/s]", PX_GE(0), PX_DEFAULT("1")), PX_KEY_END};
static const struct px_schema parabolic_keys[] = {
    PX_KEY_REAL("peak", "peak inflow speed [m/s]", PX_GE(0), PX_REQUIRED), PX_KEY_END};
static const struct px_schema inflow_types[] = {
    PX_TYPE("uniform", uniform_keys, "the same speed everywhere"),
    PX_TYPE("parabolic", parabolic_keys, "a Poiseuille profile"), PX_KEY_END};

static const char *const methods[] = {"direct", "fmm", NULL};
static const struct px_schema demo_keys[] = {
    PX_KEY_VECTOR("v_inf", "free-stream velocity [m/s]", PX_LEN(2, 2), PX_DEFAULT("[1, 0]")),
    PX_KEY_REAL("restitution", "coefficient of restitution", PX_IN(0, 1), PX_DEFAULT("0.5")),
    PX_KEY_REAL("porosity", "porosity", PX_GT(0), PX_LT(1)),
    PX_KEY_INT("order", "expansion order", PX_IN(1, 30), PX_DEFAULT("12")),
    PX_KEY_ENUM("method", methods, "N-body method", PX_DEFAULT("direct")),
    PX_KEY_LIST("bodies", &body, "solid bodies", PX_LEN(1, 3), PX_REQUIRED),
    PX_KEY_LIST("probes", &probe, "probe points"),
    PX_KEY_MAP("window", window_keys, "averaging window", PX_VALIDATE(window_check)),
    PX_KEY_VARIANT("inflow", inflow_types, "inflow profile", PX_DEFAULT("uniform")),
    PX_KEY_STRING("label", "a name used in output file names", PX_FILE_NAME, PX_WHAT("the label")),
    PX_KEY_END};
static const struct px_schema other_keys[] = {PX_KEY_INT("n", "a number", PX_DEFAULT("1")),
                                              PX_KEY_END};
static const struct px_schema sections[] = {PX_KEY_MAP("demo", demo_keys, "test solver"),
                                            PX_KEY_MAP("other", other_keys, "other solver"),
                                            PX_KEY_END};

/* ------------------------------------------------------------------------ */
/* Helpers */

static enum px_status load(const char *text, const char *const *ov, size_t n,
                           struct px_case **out) {
  px_context_clear(ctx);
  return px_case_load_string_schema(ctx, root, "case.yaml", text, strlen(text), ov, n, out);
}

/* The load must fail with PX_STATUS_CONFIG and exactly `expected`. */
static void check_error_at(int line, const char *text, const char *const *ov, size_t n,
                           const char *expected) {
  struct px_case *c = NULL;
  enum px_status st = load(text, ov, n, &c);
  PX_CHECK_MSG(st == PX_STATUS_CONFIG, "line %d: status %s (%s)", line, px_status_name(st),
               px_context_message(ctx));
  PX_CHECK_MSG(c == NULL, "line %d: a case came back from a failed load", line);
  PX_CHECK_MSG(strcmp(px_context_message(ctx), expected) == 0, "line %d: message\n%s\nexpected\n%s",
               line, px_context_message(ctx), expected);
  px_case_free(c);
}
#define CHECK_ERROR(text, expected) check_error_at(__LINE__, text, NULL, 0, expected)
#define CHECK_ERROR_SET(text, ov, expected) \
  check_error_at(__LINE__, text, ov, sizeof ov / sizeof ov[0], expected)

static const char *const valid_case =
    "# a test case\n"
    "solver: demo\n"
    "title: \"test run\"\n"
    "time:\n"
    "  dt: 1e-3\n"
    "  steps: 10\n"
    "demo:\n"
    "  v_inf: [2, 0.5]\n"
    "  bodies:\n"
    "    - type: naca\n"
    "      digits: \"0012\"\n"
    "      chord: 2\n"
    "    - type: circle\n"
    "      radius: 0.5\n";

/* The same text as valid_case with defaults filled in, in schema order. */
static const char *const valid_resolved =
    "solver: demo\n"
    "title: \"test run\"\n"
    "backend:\n"
    "  type: cpu\n"
    "  node_devices: 1\n"
    "  threads: 0\n"
    "  precision: mixed\n"
    "  workgroup: 0\n"
    "time:\n"
    "  dt: 0.001\n"
    "  steps: 10\n"
    "output:\n"
    "  dir: \"out\"\n"
    "  every: 100\n"
    "  vtk: true\n"
    "  csv: true\n"
    "  png: true\n"
    "  png_every: 0\n"
    "  checkpoint_every: 0\n"
    "  log_every: 1\n"
    "demo:\n"
    "  v_inf: [2, 0.5]\n"
    "  restitution: 0.5\n"
    "  order: 12\n"
    "  method: direct\n"
    "  bodies:\n"
    "    - type: naca\n"
    "      digits: \"0012\"\n"
    "      chord: 2\n"
    "      angle: 0\n"
    "      panels: 64\n"
    "    - type: circle\n"
    "      radius: 0.5\n"
    "      center: [0, 0]\n"
    "  window:\n"
    "    lo: 0\n"
    "    hi: 1\n"
    "  inflow:\n"
    "    type: uniform\n"
    "    speed: 1\n";

/* ------------------------------------------------------------------------ */

static void test_schemas_are_well_formed(void) {
  static const struct px_schema bad_default[] = {
      PX_KEY_REAL("dt", "time step [s]", PX_GT(0), PX_DEFAULT("-1")), PX_KEY_END};
  static const struct px_schema bad_root = PX_KEY_MAP("root", bad_default, "root");
  static const struct px_schema twice[] = {PX_KEY_INT("n", "a"), PX_KEY_INT("n", "b"), PX_KEY_END};
  static const struct px_schema twice_root = PX_KEY_MAP("root", twice, "root");
  PX_CHECK_OK(ctx, px_case_schema_check(ctx, root));
  PX_CHECK(px_case_root_schema() != NULL);
  PX_CHECK_OK(ctx, px_case_schema_check(ctx, px_case_root_schema()));
  PX_CHECK_STATUS(ctx, px_case_schema_check(ctx, &bad_root), PX_STATUS_INTERNAL);
  PX_CHECK_MSG(strcmp(px_context_message(ctx),
                      "schema: dt: bad default '-1': dt: must be > 0 (got -1)") == 0,
               "%s", px_context_message(ctx));
  PX_CHECK_STATUS(ctx, px_case_schema_check(ctx, &twice_root), PX_STATUS_INTERNAL);
  PX_CHECK(strstr(px_context_message(ctx), "n: key defined twice") != NULL);
}

static void test_valid_case_loads_with_defaults(void) {
  struct px_case *c = NULL, *again = NULL;
  double x, v[2];
  long n;
  int b, e;
  size_t count;
  const char *s;
  PX_CHECK_OK(ctx, load(valid_case, NULL, 0, &c));
  if (!c) return;
  PX_CHECK(strcmp(px_case_file(c), "case.yaml") == 0);
  PX_CHECK(px_case_solver(c) && strcmp(px_case_solver(c), "demo") == 0);

  PX_CHECK_OK(ctx, px_case_get_real(c, "time.dt", &x));
  PX_CHECK(x == 1e-3);
  PX_CHECK_OK(ctx, px_case_get_int(c, "time.steps", &n));
  PX_CHECK(n == 10);
  PX_CHECK_OK(ctx, px_case_get_real(c, "time.steps", &x)); /* an int reads as a real */
  PX_CHECK(x == 10.0);
  PX_CHECK(!px_case_has(c, "time.end"));
  PX_CHECK_STATUS(ctx, px_case_get_real(c, "time.end", &x), PX_STATUS_NOT_FOUND);
  PX_CHECK(strstr(px_context_message(ctx), "time.end") != NULL);

  /* defaults */
  PX_CHECK_OK(ctx, px_case_get_string(c, "backend.type", &s));
  PX_CHECK(strcmp(s, "cpu") == 0);
  PX_CHECK_OK(ctx, px_case_get_enum(c, "backend.precision", &e));
  PX_CHECK(e == 2); /* single, double, mixed */
  PX_CHECK_OK(ctx, px_case_get_int(c, "output.every", &n));
  PX_CHECK(n == 100);
  PX_CHECK_OK(ctx, px_case_get_bool(c, "output.png", &b));
  PX_CHECK(b == 1);
  PX_CHECK_OK(ctx, px_case_get_string(c, "output.dir", &s));
  PX_CHECK(strcmp(s, "out") == 0);
  PX_CHECK_OK(ctx, px_case_get_real(c, "demo.restitution", &x));
  PX_CHECK(x == 0.5);
  PX_CHECK_OK(ctx, px_case_get_real(c, "demo.bodies[0].angle", &x));
  PX_CHECK(x == 0.0);
  PX_CHECK_OK(ctx, px_case_get_vector(c, "demo.bodies[1].center", v, 2));
  PX_CHECK(v[0] == 0.0 && v[1] == 0.0);
  PX_CHECK_OK(ctx, px_case_get_real(c, "demo.window.hi", &x));
  PX_CHECK(x == 1.0);
  PX_CHECK(!px_case_has(c, "demo.porosity"));
  PX_CHECK_OK(ctx, px_case_get_string(c, "demo.inflow.type", &s)); /* a variant's default */
  PX_CHECK(strcmp(s, "uniform") == 0);
  PX_CHECK_OK(ctx, px_case_get_real(c, "demo.inflow.speed", &x));
  PX_CHECK(x == 1.0);

  /* given values, lists, variants, vectors */
  PX_CHECK_OK(ctx, px_case_get_string(c, "title", &s));
  PX_CHECK(strcmp(s, "test run") == 0);
  PX_CHECK_OK(ctx, px_case_get_vector(c, "demo.v_inf", v, 2));
  PX_CHECK(v[0] == 2.0 && v[1] == 0.5);
  PX_CHECK_OK(ctx, px_case_get_real(c, "demo.v_inf[1]", &x));
  PX_CHECK(x == 0.5);
  PX_CHECK_OK(ctx, px_case_count(c, "demo.v_inf", &count));
  PX_CHECK(count == 2);
  PX_CHECK_OK(ctx, px_case_count(c, "demo.bodies", &count));
  PX_CHECK(count == 2);
  PX_CHECK_OK(ctx, px_case_count(c, "demo.probes", &count)); /* absent optional list */
  PX_CHECK(count == 0);
  PX_CHECK_OK(ctx, px_case_get_string(c, "demo.bodies[0].type", &s));
  PX_CHECK(strcmp(s, "naca") == 0);
  PX_CHECK_OK(ctx, px_case_get_enum(c, "demo.bodies[0].type", &e));
  PX_CHECK(e == 2); /* circle, ellipse, naca */
  PX_CHECK_OK(ctx, px_case_get_string(c, "demo.bodies[0].digits", &s));
  PX_CHECK(strcmp(s, "0012") == 0);
  PX_CHECK_OK(ctx, px_case_get_real(c, "demo.bodies[0].chord", &x));
  PX_CHECK(x == 2.0);
  PX_CHECK_OK(ctx, px_case_get_string(c, "demo.bodies[1].type", &s));
  PX_CHECK(strcmp(s, "circle") == 0);

  /* programming errors: wrong path, wrong type, wrong size: a message, no crash */
  PX_CHECK_STATUS(ctx, px_case_get_real(c, "time.dtt", &x), PX_STATUS_INVALID);
  PX_CHECK(strcmp(px_context_message(ctx), "case key time.dtt: no such key in the case schema") ==
           0);
  PX_CHECK_STATUS(ctx, px_case_get_int(c, "time.dt", &n), PX_STATUS_INVALID);
  PX_CHECK(strcmp(px_context_message(ctx), "case key time.dt: holds a real, not an integer") == 0);
  PX_CHECK_STATUS(ctx, px_case_get_vector(c, "demo.v_inf", v, 3), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_case_get_real(c, "demo.bodies[2].chord", &x), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_case_get_real(c, "demo..x", &x), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_case_get_real(c, "", &x), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_case_get_real(c, NULL, &x), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_case_get_bool(c, "demo.bodies", &b), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_case_get_real(c, "demo.bodies[0].radius", &x), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_case_get_real(c, "time.dt[0]", &x), PX_STATUS_INVALID);

  /* resolved text: schema order, defaults, canonical values; loads back */
  PX_CHECK_MSG(strcmp(px_case_resolved_text(c), valid_resolved) == 0, "resolved:\n%s",
               px_case_resolved_text(c));
  PX_CHECK_OK(ctx, load(px_case_resolved_text(c), NULL, 0, &again));
  if (again) {
    PX_CHECK(px_case_hash(again) == px_case_hash(c));
    PX_CHECK(strcmp(px_case_resolved_text(again), px_case_resolved_text(c)) == 0);
  }
  px_case_free(again);
  px_case_free(c);
}

/* Whole numbers are written as such in the resolved text, whatever their
 * type ("[150, 70]", not "[1.5e+02, 7e+01]"); a large one keeps the shorter
 * exponent form; every value reads back to the same double. */
static void test_resolved_numbers_read_as_written(void) {
  struct px_case *c = NULL, *again = NULL;
  const char *text =
      "solver: demo\ntime: {dt: 2.5e-4, steps: 10}\n"
      "demo:\n  v_inf: [150, 7e1]\n  restitution: 1e-1\n"
      "  bodies: [{type: circle, radius: 2.1e11, center: [-3e3, 1e6]}]\n"
      "  window: {lo: 0.5, hi: 25000}\n";
  PX_CHECK_OK(ctx, load(text, NULL, 0, &c));
  if (!c) return;
  PX_CHECK_MSG(strstr(px_case_resolved_text(c), "v_inf: [150, 70]\n") &&
                   strstr(px_case_resolved_text(c), "radius: 2.1e+11\n") &&
                   strstr(px_case_resolved_text(c), "center: [-3000, 1000000]\n") &&
                   strstr(px_case_resolved_text(c), "hi: 25000\n") &&
                   strstr(px_case_resolved_text(c), "dt: 0.00025\n") &&
                   strstr(px_case_resolved_text(c), "restitution: 0.1\n"),
               "resolved:\n%s", px_case_resolved_text(c));
  PX_CHECK_OK(ctx, load(px_case_resolved_text(c), NULL, 0, &again));
  if (again) PX_CHECK(px_case_hash(again) == px_case_hash(c));
  px_case_free(again);
  px_case_free(c);
}

/* A name that becomes part of file names is one path component of safe
 * characters: never a path (no '/'), never ".." or empty, at most 64. */
static void test_file_names_are_one_safe_component(void) {
  const char *bad[] = {"\"x/../../../escaped\"",
                       "\"..\"",
                       "\".\"",
                       "\"\"",
                       "\"a b\"",
                       "\"part\\\\1\"",
                       "\"caf\xc3\xa9\"",
                       "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa"};
  char text[512];
  size_t i;
  struct px_case *c = NULL;
  for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
    snprintf(text, sizeof text,
             "solver: demo\ntime: {dt: 1, steps: 1}\n"
             "demo: {bodies: [{type: circle, radius: 1}], label: %s}\n",
             bad[i]);
    PX_CHECK_MSG(load(text, NULL, 0, &c) == PX_STATUS_CONFIG, "label %s accepted", bad[i]);
    PX_CHECK_MSG(strstr(px_context_message(ctx), "case.yaml:3:") &&
                     strstr(px_context_message(ctx),
                            "demo.label: the label becomes part of "
                            "output file names"),
                 "%s", px_context_message(ctx));
    px_case_free(c);
    c = NULL;
  }
  PX_CHECK_OK(ctx, load("solver: demo\ntime: {dt: 1, steps: 1}\n"
                        "demo: {bodies: [{type: circle, radius: 1}], label: Part_1.v-2}\n",
                        NULL, 0, &c));
  px_case_free(c);
}

/* Single-quoted scalars as YAML 1.2 reads them: '' is a quote, a line break
 * folds to a space, an empty line to a newline; runs of five and more ''
 * too (libfyaml 0.7.12 decodes those wrongly and leaks doing so). */
static void test_single_quoted_scalars(void) {
  static const struct {
    const char *yaml, *value;
  } cases[] = {{"'it''s'", "it's"},
               {"'a''''''''''''b'", "a''''''b"},
               {"''''''''''''''", "''''''"},
               {"'one\n    two'", "one two"},
               {"'one  \n\n    two  '", "one\ntwo  "},
               {"!!str 'x''y'", "x'y"},
               {"''", ""}};
  size_t i;
  for (i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    char text[256];
    struct px_case *c = NULL;
    const char *title = NULL;
    snprintf(text, sizeof text,
             "solver: demo\ntitle: %s\ntime: {dt: 1, steps: 1}\n"
             "demo: {bodies: [{type: circle, radius: 1}]}\n",
             cases[i].yaml);
    PX_CHECK_OK(ctx, load(text, NULL, 0, &c));
    if (!c) continue;
    PX_CHECK_OK(ctx, px_case_get_string(c, "title", &title));
    PX_CHECK_MSG(title && strcmp(title, cases[i].value) == 0, "%s read as [%s], expected [%s]",
                 cases[i].yaml, title ? title : "(null)", cases[i].value);
    px_case_free(c);
  }
}

static void test_hash_follows_content_not_formatting(void) {
  struct px_case *a = NULL, *b = NULL, *d = NULL;
  /* the same case written differently (flow style, comments, key order,
     explicit defaults, 0.001 vs 1e-3) */
  const char *other_form =
      "demo: {bodies: [{type: naca, digits: '0012', chord: 2.0},\n"
      "                {radius: 5e-1, type: circle}], v_inf: [2.0, 0.5], order: 12}\n"
      "time: {steps: 10, dt: 0.001}   # comment\n"
      "backend: {type: cpu}\n"
      "title: test run\n"
      "solver: demo\n";
  const char *const ov[] = {"time.steps=11"};
  PX_CHECK_OK(ctx, load(valid_case, NULL, 0, &a));
  PX_CHECK_OK(ctx, load(other_form, NULL, 0, &b));
  PX_CHECK_OK(ctx, load(valid_case, ov, 1, &d));
  if (a && b && d) {
    PX_CHECK(px_case_hash(a) == px_case_hash(b));
    PX_CHECK(px_case_hash(a) != px_case_hash(d));
    PX_CHECK(px_case_hash(a) != 0);
  }
  px_case_free(a);
  px_case_free(b);
  px_case_free(d);
}

static void test_unknown_key_suggests_sibling(void) {
  CHECK_ERROR(
      "solver: demo\n"
      "demo: {bodies: [{type: circle, radius: 1}]}\n"
      "tiem:\n"
      "  steps: 1\n"
      "time: {end: 1}\n",
      "case.yaml:3:1: tiem: unknown key, did you mean 'time'?");
  CHECK_ERROR(
      "solver: demo\n"
      "time: {steps: 1, Dt: 0.1}\n"
      "demo:\n"
      "  bodies: [{type: circle, radius: 1, centre: [0, 1]}]\n"
      "  xyzzy: 3\n",
      "case.yaml:2:18: time.Dt: unknown key, did you mean 'dt'?\n"
      "case.yaml:4:38: demo.bodies[0].centre: unknown key, did you mean 'center'?\n"
      "case.yaml:5:3: demo.xyzzy: unknown key (expected one of: v_inf, restitution, "
      "porosity, order, method, bodies, probes, window, inflow, label)");
  /* a variant with a default type: the type may be left out, not misspelt */
  CHECK_ERROR(
      "solver: demo\n"
      "time: {steps: 1}\n"
      "demo:\n"
      "  bodies: [{type: circle, radius: 1}]\n"
      "  inflow: {tpye: parabolic, peak: 2}\n",
      "case.yaml:5:12: demo.inflow.tpye: unknown key, did you mean 'type'?\n"
      "case.yaml:5:29: demo.inflow.peak: unknown key (expected one of: type, speed)");
}

static void test_wrong_types_are_named(void) {
  CHECK_ERROR(
      "solver: demo\n"
      "time: {steps: ten}\n"
      "demo: {bodies: [{type: circle, radius: 1}]}\n",
      "case.yaml:2:15: time.steps: expected an integer (got 'ten')");
  CHECK_ERROR(
      "solver: demo\n"
      "time: {steps: 1e3, dt: .nan}\n"
      "output: {vtk: maybe, dir: {a: 1}}\n"
      "demo: {bodies: {type: circle}, v_inf: 5, restitution: [1]}\n",
      "case.yaml:2:15: time.steps: expected an integer (got '1e3')\n"
      "case.yaml:2:24: time.dt: expected a finite real number (got '.nan')\n"
      "case.yaml:3:15: output.vtk: expected true or false (got 'maybe')\n"
      "case.yaml:3:27: output.dir: expected a string (got a map)\n"
      "case.yaml:4:16: demo.bodies: expected a list (got a map)\n"
      "case.yaml:4:39: demo.v_inf: expected a list of 2 numbers (got '5')\n"
      "case.yaml:4:55: demo.restitution: expected a real number (got a list)");
  CHECK_ERROR(
      "solver: demo\n"
      "backend: {type: [cpu]}\n"
      "time: {steps: 1, '': 2}\n"
      "demo: {bodies: [{type: circle, radius: 1}]}\n",
      "case.yaml:2:17: backend.type: expected one of: cpu, opencl (got a list)\n"
      "case.yaml:3:18: time.'': unknown key (expected one of: dt, steps, end)");
  CHECK_ERROR(
      "solver: demo\n"
      "time: 5\n"
      "demo: {bodies: [{type: circle, radius: 1}]}\n",
      "case.yaml:2:7: time: expected a map (got '5')");
  CHECK_ERROR("- solver\n- demo\n", "case.yaml:1:1: expected a map (got a list)");
  /* accepted spellings: yes/on/off, reals written as integers, quoted numbers */
  {
    struct px_case *c = NULL;
    int b = 0;
    double x = 0;
    PX_CHECK_OK(ctx, load("solver: demo\ntime: {steps: 1, dt: 2}\n"
                          "output: {vtk: off, csv: Yes, png: ON}\n"
                          "demo: {bodies: [{type: circle, radius: \"1.5\"}]}\n",
                          NULL, 0, &c));
    if (c) {
      PX_CHECK_OK(ctx, px_case_get_bool(c, "output.vtk", &b));
      PX_CHECK(b == 0);
      PX_CHECK_OK(ctx, px_case_get_bool(c, "output.csv", &b));
      PX_CHECK(b == 1);
      PX_CHECK_OK(ctx, px_case_get_real(c, "time.dt", &x));
      PX_CHECK(x == 2.0);
      PX_CHECK_OK(ctx, px_case_get_real(c, "demo.bodies[0].radius", &x));
      PX_CHECK(x == 1.5);
    }
    px_case_free(c);
  }
}

static void test_ranges_inclusive_and_exclusive(void) {
  CHECK_ERROR(
      "solver: demo\n"
      "time: {steps: 0, dt: -0.001}\n"
      "demo:\n"
      "  restitution: 1.2\n"
      "  porosity: 1\n"
      "  order: 31\n"
      "  bodies: [{type: naca, digits: '0012', angle: -90.5}]\n",
      "case.yaml:2:15: time.steps: must be in [1, 1e+12] (got 0)\n"
      "case.yaml:2:22: time.dt: must be > 0 (got -0.001)\n"
      "case.yaml:4:16: demo.restitution: must be in [0, 1] (got 1.2)\n"
      "case.yaml:5:13: demo.porosity: must be in (0, 1) (got 1)\n"
      "case.yaml:6:10: demo.order: must be in [1, 30] (got 31)\n"
      "case.yaml:7:48: demo.bodies[0].angle: must be in [-90, 90] (got -90.5)");
  CHECK_ERROR(
      "solver: demo\ntime: {steps: 1}\n"
      "demo: {porosity: 0, bodies: [{type: circle, radius: 1}]}\n",
      "case.yaml:3:18: demo.porosity: must be in (0, 1) (got 0)");
  { /* the bounds themselves, where inclusive */
    struct px_case *c = NULL;
    PX_CHECK_OK(ctx, load("solver: demo\ntime: {steps: 1}\n"
                          "demo: {restitution: 1, order: 1, porosity: 0.999,\n"
                          "       bodies: [{type: naca, digits: '0012', angle: 90}]}\n",
                          NULL, 0, &c));
    px_case_free(c);
    PX_CHECK_OK(ctx, load("solver: demo\ntime: {steps: 1}\n"
                          "demo: {restitution: 0, order: 30, porosity: 1e-9,\n"
                          "       bodies: [{type: naca, digits: '0012', angle: -90}]}\n",
                          NULL, 0, &c));
    px_case_free(c);
  }
}

static void test_missing_required_keys(void) {
  CHECK_ERROR("time: {steps: 1}\n", "case.yaml:1:1: missing required key 'solver' (solver to run)");
  CHECK_ERROR(
      "solver: demo\n"
      "time: {steps: 1}\n"
      "demo:\n"
      "  bodies:\n"
      "    - type: circle\n"
      "    - type: naca\n"
      "      chord: 1\n"
      "    - {}\n",
      "case.yaml:5:7: demo.bodies[0]: missing required key 'radius' (radius [m])\n"
      "case.yaml:6:7: demo.bodies[1]: missing required key 'digits' (NACA 4-digit "
      "designation)\n"
      "case.yaml:8:7: demo.bodies[2]: missing required key 'type' (body type, one of: "
      "circle, ellipse, naca)");
  /* an absent section whose keys are required */
  CHECK_ERROR("solver: demo\ntime: {steps: 1}\n",
              "case.yaml:1:1: demo: missing required key 'bodies' (solid bodies)");
}

static void test_enum_and_variant_typos_suggest(void) {
  CHECK_ERROR("solver: dmeo\ntime: {steps: 1}\n",
              "case.yaml:1:9: solver: unknown solver 'dmeo', did you mean 'demo'? (choices: "
              "demo, other)");
  CHECK_ERROR(
      "solver: demo\n"
      "backend: {type: opncl, precision: quad}\n"
      "time: {steps: 1}\n"
      "demo:\n"
      "  method: FMM\n"
      "  bodies: [{type: nacca, digits: '0012'}, {type: square}]\n",
      "case.yaml:2:17: backend.type: unknown value 'opncl', did you mean 'opencl'? "
      "(choices: cpu, opencl)\n"
      "case.yaml:2:35: backend.precision: unknown value 'quad' (choices: single, double, "
      "mixed)\n"
      "case.yaml:5:11: demo.method: unknown value 'FMM', did you mean 'fmm'? (choices: "
      "direct, fmm)\n"
      "case.yaml:6:19: demo.bodies[0].type: unknown body type 'nacca', did you mean "
      "'naca'? (choices: circle, ellipse, naca)\n"
      "case.yaml:6:50: demo.bodies[1].type: unknown body type 'square' (choices: circle, "
      "ellipse, naca)");
  /* the section of another solver */
  CHECK_ERROR("solver: other\ntime: {steps: 1}\ndemo: {bodies: []}\n",
              "case.yaml:3:1: demo: this section is for solver 'demo', but solver is 'other' "
              "(remove the section or change the solver)");
}

static void test_list_and_vector_lengths(void) {
  CHECK_ERROR("solver: demo\ntime: {steps: 1}\ndemo: {bodies: []}\n",
              "case.yaml:3:16: demo.bodies: must have at least 1 item (got 0)");
  CHECK_ERROR(
      "solver: demo\ntime: {steps: 1}\n"
      "demo:\n"
      "  bodies:\n"
      "    - {type: circle, radius: 1}\n"
      "    - {type: circle, radius: 2}\n"
      "    - {type: circle, radius: 3}\n"
      "    - {type: circle, radius: 4, center: [1, 2, 3]}\n"
      "  v_inf: [1]\n"
      "  probes: [[0, 0], [1, x]]\n",
      "case.yaml:5:5: demo.bodies: must have at most 3 items (got 4)\n"
      "case.yaml:8:41: demo.bodies[3].center: must have exactly 2 components (got 3)\n"
      "case.yaml:9:10: demo.v_inf: must have exactly 2 components (got 1)\n"
      "case.yaml:10:24: demo.probes[1][1]: expected a real number (got 'x')");
}

static void test_duplicate_keys(void) {
  CHECK_ERROR(
      "solver: demo\n"
      "time:\n"
      "  dt: 0.1\n"
      "  dt: 0.2\n"
      "  steps: 1\n"
      "demo: {bodies: [{type: circle, radius: 1, type: naca}]}\n",
      "case.yaml:4:3: time.dt: duplicate key (first given at line 3)\n"
      "case.yaml:6:43: demo.bodies[0].type: duplicate key (first given at line 6)");
}

static void test_yaml_syntax_errors_have_positions(void) {
  CHECK_ERROR(
      "solver: demo\n"
      "time:\n"
      "  steps: [1, 2\n"
      "demo: 3\n",
      "case.yaml:5:1: YAML syntax error: flow sequence without a closing bracket");
  CHECK_ERROR(
      "solver: demo\n"
      "time:\n"
      "\tsteps: 1\n",
      "case.yaml:3:1: YAML syntax error: tab character may not be used as indentation");
  CHECK_ERROR(
      "solver: demo\n"
      "title: \"unclosed\n",
      "case.yaml:2:9: YAML syntax error: double-quoted scalar without closing quote");
  CHECK_ERROR("solver: demo\n---\nsolver: other\n",
              "case.yaml:2:1: only one YAML document is allowed in a case file (found a second "
              "'---')");
  CHECK_ERROR("solver: demo\ntitle: *nowhere\n",
              "case.yaml:2:8: unknown alias '*nowhere' (no anchor '&nowhere' before it)");
  CHECK_ERROR("solver: demo\ntitle: !custom x\n",
              "case.yaml:2:8: unsupported tag '!custom' (partix knows only !!str)");
  CHECK_ERROR("solver: demo\n? [a, b]\n: 1\n",
              "case.yaml:2:3: a key must be a plain name, not a list");
}

static void test_errors_are_all_reported_and_capped(void) {
  char text[4096];
  size_t len, i;
  struct px_case *c = NULL;
  const char *msg, *p;
  size_t lines = 0;
  /* 30 unknown keys: 20 shown, the rest counted */
  len = (size_t)snprintf(text, sizeof text,
                         "solver: demo\ntime: {steps: 1}\n"
                         "demo: {bodies: [{type: circle, radius: 1}]}\n");
  for (i = 0; i < 30; ++i)
    len += (size_t)snprintf(text + len, sizeof text - len, "junk%zu: 1\n", i);
  PX_CHECK_STATUS(ctx, load(text, NULL, 0, &c), PX_STATUS_CONFIG);
  msg = px_context_message(ctx);
  for (p = msg; *p; ++p) lines += *p == '\n';
  PX_CHECK_MSG(lines == 20, "%zu newlines in\n%s", lines, msg);
  PX_CHECK(strncmp(msg,
                   "case.yaml:4:1: junk0: unknown key (expected one of: solver, title, "
                   "backend, time, output, demo, other)\n",
                   strlen("case.yaml:4:1: junk0: unknown key (expected one of: solver, title, "
                          "backend, time, output, demo, other)\n")) == 0);
  PX_CHECK(strstr(msg, "\ncase.yaml:23:1: junk19: unknown key") != NULL);
  PX_CHECK(strstr(msg, "junk20") == NULL);
  p = strrchr(msg, '\n');
  PX_CHECK(p && strcmp(p, "\n(10 more errors not shown)") == 0);
}

static void test_overrides(void) {
  struct px_case *c = NULL;
  const char *const ov[] = {
      "time.steps=20",                              /* existing key */
      "output.dir=results",                         /* key of an absent map */
      "title=overridden: yes",                      /* a value that is YAML */
      "demo.bodies[1].radius=2",                    /* list item */
      "demo.v_inf=[1, -1]",                         /* vector */
      "demo.bodies[2]={type: ellipse, a: 2, b: 1}", /* append */
      "backend.type=opencl",
      "demo.window.lo=0.5",
  };
  long n;
  double x, v[2];
  const char *s;
  size_t count;
  PX_CHECK_STATUS(ctx, load(valid_case, ov, 8, &c), PX_STATUS_CONFIG);
  /* "title=overridden: yes" is a map: quoting is needed */
  PX_CHECK_MSG(strcmp(px_context_message(ctx),
                      "--set title=overridden: yes: title: expected a string (got a map)") == 0,
               "%s", px_context_message(ctx));
  {
    const char *const ov2[] = {
        "time.steps=20",           "output.dir=results",
        "title='overridden: yes'", "demo.bodies[1].radius=2",
        "demo.v_inf=[1, -1]",      "demo.bodies[2]={type: ellipse, a: 2, b: 1}",
        "backend.type=opencl",     "demo.window.lo=0.5",
    };
    PX_CHECK_OK(ctx, load(valid_case, ov2, 8, &c));
  }
  if (!c) return;
  PX_CHECK_OK(ctx, px_case_get_int(c, "time.steps", &n));
  PX_CHECK(n == 20);
  PX_CHECK_OK(ctx, px_case_get_string(c, "output.dir", &s));
  PX_CHECK(strcmp(s, "results") == 0);
  PX_CHECK_OK(ctx, px_case_get_string(c, "title", &s));
  PX_CHECK(strcmp(s, "overridden: yes") == 0);
  PX_CHECK_OK(ctx, px_case_get_real(c, "demo.bodies[1].radius", &x));
  PX_CHECK(x == 2.0);
  PX_CHECK_OK(ctx, px_case_get_vector(c, "demo.v_inf", v, 2));
  PX_CHECK(v[0] == 1.0 && v[1] == -1.0);
  PX_CHECK_OK(ctx, px_case_count(c, "demo.bodies", &count));
  PX_CHECK(count == 3);
  PX_CHECK_OK(ctx, px_case_get_string(c, "demo.bodies[2].type", &s));
  PX_CHECK(strcmp(s, "ellipse") == 0);
  PX_CHECK_OK(ctx, px_case_get_string(c, "backend.type", &s));
  PX_CHECK(strcmp(s, "opencl") == 0);
  PX_CHECK_OK(ctx, px_case_get_real(c, "demo.window.lo", &x));
  PX_CHECK(x == 0.5);
  PX_CHECK_OK(ctx, px_case_get_real(c, "time.dt", &x)); /* untouched */
  PX_CHECK(x == 1e-3);
  px_case_free(c);

  {
    const char *const bad_value[] = {"time.dt=abc"};
    CHECK_ERROR_SET(valid_case, bad_value,
                    "--set time.dt=abc: time.dt: expected a real number (got 'abc')");
  }
  {
    const char *const bad[] = {"time.dt",
                               "time..dt=1",
                               "demo.bodies[5].radius=1",
                               "time.steps.x=1",
                               "tiem.steps=3",
                               "demo.v_inf=[1, 0",
                               "demo.bodies[0].chord=-1",
                               "probes[2].x=1",
                               "demo.bodies.1.radius=2"};
    CHECK_ERROR_SET(valid_case, bad,
                    "--set time.dt: missing '=' (expected --set key.path=value, e.g. --set "
                    "time.steps=100)\n"
                    "--set time..dt=1: malformed key path 'time..dt' (expected key.path=value, "
                    "e.g. time.dt=0.001 or vortex.bodies[0].angle=5)\n"
                    "--set demo.bodies[5].radius=1: demo.bodies: index [5] is out of range (the "
                    "list has 2 items; [2] adds one)\n"
                    "--set time.steps.x=1: time.steps: is a single value, not a map: cannot set "
                    "'x' inside it\n"
                    "--set tiem.steps=3: tiem: unknown key, did you mean 'time'?\n"
                    "--set demo.v_inf=[1, 0: YAML syntax error: flow sequence without a closing "
                    "bracket\n"
                    "--set demo.bodies[0].chord=-1: demo.bodies[0].chord: must be > 0 (got -1)\n"
                    /* a failed override leaves nothing behind (no "probes: unknown key") */
                    "--set probes[2].x=1: probes: index [2] is out of range (the list has 0 "
                    "items; [0] adds one)\n"
                    "--set demo.bodies.1.radius=2: demo.bodies: is a list, not a map: cannot set "
                    "'1' inside it (an item of a list is demo.bodies[1])");
  }
  {
    const char *const bad[] = {"demo.bodies[0].chord=-1"};
    CHECK_ERROR_SET(valid_case, bad,
                    "--set demo.bodies[0].chord=-1: demo.bodies[0].chord: must be > 0 (got -1)");
  }
  { /* a later override wins; the file's other errors still show */
    const char *const twice[] = {"time.steps=5", "time.steps=7"};
    PX_CHECK_OK(ctx, load(valid_case, twice, 2, &c));
    if (c) {
      PX_CHECK_OK(ctx, px_case_get_int(c, "time.steps", &n));
      PX_CHECK(n == 7);
    }
    px_case_free(c);
  }
}

static void test_steps_and_end_cross_check(void) {
  CHECK_ERROR(
      "solver: demo\n"
      "time:\n"
      "  steps: 10\n"
      "  end: 1.5\n"
      "demo: {bodies: [{type: circle, radius: 1}]}\n",
      "case.yaml:2:1: time: give either 'steps' or 'end', not both");
  CHECK_ERROR(
      "solver: demo\n"
      "time:\n"
      "  dt: 0.1\n"
      "demo: {bodies: [{type: circle, radius: 1}], window: {lo: 2}}\n",
      "case.yaml:2:1: time: missing 'steps' or 'end' (give exactly one: the number of "
      "time steps, or the end time [s])\n"
      "case.yaml:4:45: demo.window: lo must be below hi (got lo 2, hi 1)");
  {
    struct px_case *c = NULL;
    double x;
    PX_CHECK_OK(ctx, load("solver: demo\ntime: {end: 2.5}\n"
                          "demo: {bodies: [{type: circle, radius: 1}]}\n",
                          NULL, 0, &c));
    if (c) {
      PX_CHECK_OK(ctx, px_case_get_real(c, "time.end", &x));
      PX_CHECK(x == 2.5);
      PX_CHECK(!px_case_has(c, "time.steps"));
    }
    px_case_free(c);
  }
  { /* an override that resolves the conflict */
    const char *const ov[] = {"time={end: 3}"};
    struct px_case *c = NULL;
    PX_CHECK_OK(ctx, load("solver: demo\ntime: {steps: 1, end: 1}\n"
                          "demo: {bodies: [{type: circle, radius: 1}]}\n",
                          ov, 1, &c));
    px_case_free(c);
  }
}

static void test_fail_points_at_nested_list_items(void) {
  struct px_case *c = NULL;
  const char *const ov[] = {"demo.bodies[1].radius=0.75"};
  PX_CHECK_OK(ctx, load(valid_case, ov, 1, &c));
  if (!c) return;
  px_context_clear(ctx);
  PX_CHECK_STATUS(ctx, px_case_fail(c, "demo.bodies[0]", "contour intersects itself"),
                  PX_STATUS_CONFIG);
  PX_CHECK_MSG(strcmp(px_context_message(ctx),
                      "case.yaml:10:7: demo.bodies[0]: contour intersects itself") == 0,
               "%s", px_context_message(ctx));
  /* the next failure adds a line; lines stay in file order */
  PX_CHECK_STATUS(ctx, px_case_fail(c, "demo.bodies[0].chord", "chord %g is too long", 2.0),
                  PX_STATUS_CONFIG);
  PX_CHECK_MSG(strcmp(px_context_message(ctx),
                      "case.yaml:10:7: demo.bodies[0]: contour intersects itself\n"
                      "case.yaml:12:14: demo.bodies[0].chord: chord 2 is too long") == 0,
               "%s", px_context_message(ctx));
  px_case_free(c);

  PX_CHECK_OK(ctx, load(valid_case, ov, 1, &c));
  if (!c) return;
  /* a value from --set names the --set */
  PX_CHECK_STATUS(ctx, px_case_fail(c, "demo.bodies[1].radius", "overlaps body 0"),
                  PX_STATUS_CONFIG);
  PX_CHECK_MSG(
      strcmp(px_context_message(ctx),
             "--set demo.bodies[1].radius=0.75: demo.bodies[1].radius: overlaps body 0") == 0,
      "%s", px_context_message(ctx));
  px_case_free(c);

  PX_CHECK_OK(ctx, load(valid_case, NULL, 0, &c));
  if (!c) return;
  /* a default has no position: its nearest given parent, marked as default */
  PX_CHECK_STATUS(ctx, px_case_fail(c, "demo.bodies[1].center", "outside the domain"),
                  PX_STATUS_CONFIG);
  PX_CHECK_MSG(strcmp(px_context_message(ctx),
                      "case.yaml:13:7: demo.bodies[1].center: outside the domain (default "
                      "value)") == 0,
               "%s", px_context_message(ctx));
  px_case_free(c);

  PX_CHECK_OK(ctx, load(valid_case, NULL, 0, &c));
  if (!c) return;
  /* a vector value points at itself, a top-level map at its key */
  PX_CHECK_STATUS(ctx, px_case_fail(c, "demo.v_inf", "too fast"), PX_STATUS_CONFIG);
  PX_CHECK_MSG(strcmp(px_context_message(ctx), "case.yaml:8:10: demo.v_inf: too fast") == 0, "%s",
               px_context_message(ctx));
  px_case_free(c);
}

static void test_platform_root_without_solvers(void) {
  struct px_case *c = NULL;
  FILE *f;
  const char *const ov[] = {"time.steps=3"};
  PX_CHECK_STATUS(ctx,
                  px_case_load_string(ctx, "case.yaml", "solver: nosuch\ntime: {steps: 1}\n",
                                      strlen("solver: nosuch\ntime: {steps: 1}\n"), NULL, 0, &c),
                  PX_STATUS_CONFIG);
  /* the list of available solvers depends on the registry: compare up to it */
  PX_CHECK_MSG(strncmp(px_context_message(ctx), "case.yaml:1:9: solver: unknown solver 'nosuch'",
                       strlen("case.yaml:1:9: solver: unknown solver 'nosuch'")) == 0,
               "%s", px_context_message(ctx));
  PX_CHECK(c == NULL);

  /* the public entry point reads a file; messages carry its name */
  f = fopen("config_case_test.yaml", "wb");
  PX_CHECK(f != NULL);
  if (!f) return;
  fputs("solver: nosuch\ntime:\n  dt: 0\n", f);
  fclose(f);
  PX_CHECK_STATUS(ctx, px_case_load(ctx, "config_case_test.yaml", ov, 1, &c), PX_STATUS_CONFIG);
  PX_CHECK_MSG(
      strncmp(px_context_message(ctx), "config_case_test.yaml:1:9: solver: unknown solver 'nosuch'",
              strlen("config_case_test.yaml:1:9: solver: unknown solver 'nosuch'")) == 0 &&
          strstr(px_context_message(ctx),
                 "\nconfig_case_test.yaml:3:7: time.dt: must be > 0 (got 0)") != NULL,
      "%s", px_context_message(ctx));
  remove("config_case_test.yaml");
  PX_CHECK_STATUS(ctx, px_case_load(ctx, "no_such_case.yaml", NULL, 0, &c), PX_STATUS_IO);
  PX_CHECK(strstr(px_context_message(ctx), "no_such_case.yaml") != NULL);
  PX_CHECK_STATUS(ctx, px_case_load(ctx, ".", NULL, 0, &c), PX_STATUS_IO);
}

static void test_write_resolved_and_print_keys(void) {
  struct px_case *c = NULL;
  char buf[4096];
  size_t n;
  FILE *f;
  PX_CHECK_OK(ctx, load(valid_case, NULL, 0, &c));
  if (!c) return;
  PX_CHECK_OK(ctx, px_case_write_resolved(c, "config_resolved_test.yaml"));
  f = fopen("config_resolved_test.yaml", "rb");
  PX_CHECK(f != NULL);
  if (f) {
    n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    PX_CHECK(strcmp(buf, valid_resolved) == 0);
  }
  remove("config_resolved_test.yaml");
  px_case_free(c);

  f = tmpfile();
  PX_CHECK(f != NULL);
  if (!f) return;
  PX_CHECK_OK(ctx, px_case_print_schema(root, NULL, f));
  PX_CHECK(px_case_print_schema(root, "nothing", f) == PX_STATUS_NOT_FOUND);
  PX_CHECK_OK(ctx, px_case_print_keys(f, "time"));
  rewind(f);
  n = fread(buf, 1, sizeof buf - 1, f);
  buf[n] = '\0';
  fclose(f);
  PX_CHECK(strstr(buf, "time.dt                            real > 0") != NULL);
  PX_CHECK(strstr(buf, "time step [s]") != NULL);
  PX_CHECK(strstr(buf, "demo.restitution                   real in [0, 1], default 0.5") != NULL);
  PX_CHECK(strstr(buf, "backend.type                       cpu|opencl, default cpu") != NULL);
  PX_CHECK(strstr(buf, "demo.bodies[] with type: naca") != NULL);
  PX_CHECK(strstr(buf, "demo.bodies[].digits               string, required") != NULL);
}

/* A key's doc string by its path (the sweep's axis units): list indices in
 * any form, a variant's keys, and NULL for what is not a key. */
static void test_key_doc_by_path(void) {
  const char *d = px_schema_key_doc(root, "time.dt");
  const char *f = px_case_key_doc("granular.bodies[0].motion.frequency");
  PX_CHECK_MSG(d && strncmp(d, "time step [s] (", 15) == 0, "%s", d ? d : "(null)");
  PX_CHECK(px_schema_key_doc(root, "demo.bodies[2].digits") != NULL);
  PX_CHECK(px_schema_key_doc(root, "demo.bodies[].digits") ==
           px_schema_key_doc(root, "demo.bodies[7].digits"));
  PX_CHECK(px_schema_key_doc(root, "time") != NULL);
  PX_CHECK(px_schema_key_doc(root, "time.dt.more") == NULL);
  PX_CHECK(px_schema_key_doc(root, "time.nope") == NULL);
  PX_CHECK(px_schema_key_doc(root, "") == NULL);
  PX_CHECK(px_schema_key_doc(root, "demo.bodies[2.digits") == NULL);
  /* this build's root, through the public API */
  PX_CHECK_MSG(f && strcmp(f, "frequency [Hz]") == 0, "%s", f ? f : "(null)");
  PX_CHECK(px_case_key_doc("granular.nope") == NULL);
}

static void test_edit_distance(void) {
  PX_CHECK(px_case_edit_distance("tiem", 4, "time", 4) == 1);
  PX_CHECK(px_case_edit_distance("kitten", 6, "sitting", 7) == 3);
  PX_CHECK(px_case_edit_distance("ca", 2, "abc", 3) == 3); /* OSA, not full Damerau */
  PX_CHECK(px_case_edit_distance("Time", 4, "time", 4) == 0);
  PX_CHECK(px_case_edit_distance("", 0, "abc", 3) == 3);
}

int main(void) {
  if (px_context_create(&ctx) != PX_STATUS_OK) return EXIT_FAILURE;
  root = px_case_root_schema_build(sections, &storage);
  PX_CHECK(root != NULL);
  if (!root) return px_test_report("test_config_case");
  test_schemas_are_well_formed();
  test_valid_case_loads_with_defaults();
  test_hash_follows_content_not_formatting();
  test_unknown_key_suggests_sibling();
  test_wrong_types_are_named();
  test_ranges_inclusive_and_exclusive();
  test_missing_required_keys();
  test_enum_and_variant_typos_suggest();
  test_list_and_vector_lengths();
  test_duplicate_keys();
  test_yaml_syntax_errors_have_positions();
  test_errors_are_all_reported_and_capped();
  test_overrides();
  test_steps_and_end_cross_check();
  test_fail_points_at_nested_list_items();
  test_platform_root_without_solvers();
  test_write_resolved_and_print_keys();
  test_key_doc_by_path();
  test_resolved_numbers_read_as_written();
  test_file_names_are_one_safe_component();
  test_single_quoted_scalars();
  test_edit_distance();
  PX_CHECK(px_mem_current(ctx, "case") == 0); /* everything freed */
  px_context_free(ctx);
  return px_test_report("test_config_case");
}
