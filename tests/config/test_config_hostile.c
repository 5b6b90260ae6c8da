/* Case files against hostile input: deep nesting, binary junk, alias bombs,
 * huge values, odd scalars, random mutations of a valid case. The loader must
 * never crash, always answer OK or CONFIG, and every CONFIG message must give
 * a location. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/schema.h"
#include "px_test.h"

static struct px_context *ctx;
static struct px_case_root_storage storage;
static const struct px_schema *root;

static const struct px_schema circle_keys[] = {
    PX_KEY_REAL("radius", "radius [m]", PX_GT(0), PX_REQUIRED),
    PX_KEY_VECTOR("center", "centre [m]", PX_LEN(2, 2), PX_DEFAULT("[0, 0]")), PX_KEY_END};
static const struct px_schema body_types[] = {PX_TYPE("circle", circle_keys, "a circle"),
                                              PX_KEY_END};
static const struct px_schema body = PX_KEY_VARIANT("body", body_types, "a solid body");
static const struct px_schema probe = PX_KEY_VECTOR("probe", "probe point [m]", PX_LEN(2, 2));
static const struct px_schema demo_keys[] = {
    PX_KEY_VECTOR("v_inf", "free-stream velocity [m/s]", PX_LEN(2, 2), PX_DEFAULT("[1, 0]")),
    PX_KEY_LIST("bodies", &body, "solid bodies"), PX_KEY_LIST("probes", &probe, "probe points"),
    PX_KEY_END};
static const struct px_schema sections[] = {PX_KEY_MAP("demo", demo_keys, "test solver"),
                                            PX_KEY_END};

static unsigned long rng_state = 12345;
static unsigned long rng(void) {
  rng_state = rng_state * 6364136223846793005ul + 1442695040888963407ul;
  return rng_state >> 33;
}

static enum px_status load_n(const char *text, size_t len, const char *const *ov, size_t n,
                             struct px_case **out) {
  px_context_clear(ctx);
  return px_case_load_string_schema(ctx, root, "case.yaml", text, len, ov, n, out);
}

/* A CONFIG message: non-empty, every line located (file or --set). */
static int located(const char *msg) {
  const char *line = msg;
  if (!*msg) return 0;
  while (line && *line) {
    if (strncmp(line, "case.yaml:", 10) != 0 && strncmp(line, "--set ", 6) != 0 && line[0] != '(')
      return 0;
    line = strchr(line, '\n');
    if (line) ++line;
  }
  return 1;
}

/* Load must end in OK (then the resolved text must reload to the same hash)
 * or in CONFIG with located messages. */
static void check_survives(int line, const char *text, size_t len) {
  struct px_case *c = NULL, *again = NULL;
  enum px_status st = load_n(text, len, NULL, 0, &c);
  PX_CHECK_MSG(st == PX_STATUS_OK || st == PX_STATUS_CONFIG, "line %d: status %s: %s", line,
               px_status_name(st), px_context_message(ctx));
  if (st == PX_STATUS_CONFIG)
    PX_CHECK_MSG(located(px_context_message(ctx)), "line %d: unlocated message:\n%s", line,
                 px_context_message(ctx));
  if (c) {
    const char *r = px_case_resolved_text(c);
    PX_CHECK_OK(ctx, load_n(r, strlen(r), NULL, 0, &again));
    if (again) PX_CHECK(px_case_hash(again) == px_case_hash(c));
    px_case_free(again);
  }
  px_case_free(c);
}

static void check_message(int line, const char *text, size_t len, const char *expected) {
  struct px_case *c = NULL;
  enum px_status st = load_n(text, len, NULL, 0, &c);
  PX_CHECK_MSG(st == PX_STATUS_CONFIG, "line %d: status %s", line, px_status_name(st));
  PX_CHECK_MSG(strcmp(px_context_message(ctx), expected) == 0, "line %d: message\n%s\nexpected\n%s",
               line, px_context_message(ctx), expected);
  px_case_free(c);
}
#define CHECK_MESSAGE(text, expected) check_message(__LINE__, text, strlen(text), expected)

static char *repeat(const char *head, const char *unit, size_t n, const char *tail) {
  size_t hl = strlen(head), ul = strlen(unit), tl = strlen(tail), i;
  char *s = malloc(hl + ul * n + tl + 1);
  if (!s) return NULL;
  memcpy(s, head, hl);
  for (i = 0; i < n; ++i) memcpy(s + hl + i * ul, unit, ul);
  memcpy(s + hl + n * ul, tail, tl + 1);
  return s;
}

static void test_deep_nesting_is_refused(void) {
  char *open = repeat("solver: demo\ndemo: ", "[", 100000, "");
  char *block = NULL;
  size_t i, len = 0;
  struct px_case *c = NULL;
  if (!open) return;
  PX_CHECK_STATUS(ctx, load_n(open, strlen(open), NULL, 0, &c), PX_STATUS_CONFIG);
  PX_CHECK_MSG(
      strcmp(px_context_message(ctx), "case.yaml:2:70: nesting deeper than 64 levels") == 0, "%s",
      px_context_message(ctx));
  free(open);
  block = malloc(200 * 210);
  if (!block) return;
  for (i = 0; i < 200; ++i) len += (size_t)sprintf(block + len, "%*sk%zu:\n", (int)i, "", i);
  PX_CHECK_STATUS(ctx, load_n(block, len, NULL, 0, &c), PX_STATUS_CONFIG);
  PX_CHECK(strstr(px_context_message(ctx), "nesting deeper than 64 levels") != NULL);
  free(block);
}

static void test_binary_junk(void) {
  static const char nul_text[] = "solver: demo\ntit\0le: x\n";
  char junk[4096];
  size_t i, k;
  check_message(__LINE__, nul_text, sizeof nul_text - 1,
                "case.yaml:2:4: the text contains a NUL byte (is this a binary file?)");
  CHECK_MESSAGE("solver: demo\ntitle: \xff\xfe\x80\n",
                "case.yaml:2:8: invalid UTF-8 byte 0xFF (case files are UTF-8 text)");
  CHECK_MESSAGE("solver: d\xc3\xa9mo\n\xe2\x82\xac: \xed\xa0\x80\n", /* a surrogate */
                "case.yaml:2:4: invalid UTF-8 byte 0xED (case files are UTF-8 text)");
  CHECK_MESSAGE("%\xdd", /* made libfyaml 0.7.12 loop forever */
                "case.yaml:1:2: invalid UTF-8 byte 0xDD (case files are UTF-8 text)");
  for (k = 0; k < 200; ++k) {
    size_t len = 1 + rng() % sizeof junk;
    for (i = 0; i < len; ++i) junk[i] = (char)(rng() & 0xFF);
    if (k % 2) /* also without NULs, to reach the YAML parser */
      for (i = 0; i < len; ++i)
        if (!junk[i]) junk[i] = ' ';
    check_survives(__LINE__, junk, len);
  }
}

static void test_alias_bomb_is_bounded(void) {
  const char *bomb =
      "a: &a [x, x, x, x, x, x, x, x, x, x]\n"
      "b: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
      "c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b, *b]\n"
      "d: &d [*c, *c, *c, *c, *c, *c, *c, *c, *c, *c]\n"
      "e: &e [*d, *d, *d, *d, *d, *d, *d, *d, *d, *d]\n"
      "f: &f [*e, *e, *e, *e, *e, *e, *e, *e, *e, *e]\n"
      "g: &g [*f, *f, *f, *f, *f, *f, *f, *f, *f, *f]\n"
      "h: &h [*g, *g, *g, *g, *g, *g, *g, *g, *g, *g]\n"
      "i: &i [*h, *h, *h, *h, *h, *h, *h, *h, *h, *h]\n";
  struct px_case *c = NULL;
  PX_CHECK_STATUS(ctx, load_n(bomb, strlen(bomb), NULL, 0, &c), PX_STATUS_CONFIG);
  /* the 8th copy of *e in f: a..e hold 123455 values, f 1 + 8 x 111111 */
  PX_CHECK_MSG(strcmp(px_context_message(ctx),
                      "case.yaml:6:36: too many values in one case (more than 1000000)") == 0,
               "%s", px_context_message(ctx));
  /* aliases as such work */
  PX_CHECK_OK(ctx, load_n("solver: demo\ntime: {steps: 1}\n"
                          "demo:\n  v_inf: &v [1, 2]\n  probes: [*v, *v]\n",
                          strlen("solver: demo\ntime: {steps: 1}\n"
                                 "demo:\n  v_inf: &v [1, 2]\n  probes: [*v, *v]\n"),
                          NULL, 0, &c));
  px_case_free(c);
  { /* each alias of an alias nests one level deeper: bounded too */
    char *chain = repeat("x0: &a0 ", "[", 60, "");
    char *full = chain ? malloc(strlen(chain) + 200) : NULL;
    if (full) {
      size_t len = (size_t)sprintf(full, "%s", chain), i;
      for (i = 0; i < 60; ++i) full[len++] = ']';
      full[len++] = '\n';
      for (i = 1; i <= 5; ++i)
        len += (size_t)sprintf(full + len, "x%zu: &a%zu [*a%zu]\n", i, i, i - 1);
      PX_CHECK_STATUS(ctx, load_n(full, len, NULL, 0, &c), PX_STATUS_CONFIG);
      PX_CHECK_MSG(strcmp(px_context_message(ctx),
                          "case.yaml:5:10: nesting deeper than 64 levels (through aliases)") == 0,
                   "%s", px_context_message(ctx));
    }
    free(chain);
    free(full);
  }
  CHECK_MESSAGE("solver: demo\ntime: &t {steps: 1, x: *t}\n",
                "case.yaml:2:24: alias '*t' refers to a node that contains it");
}

static void test_huge_values(void) {
  char *probes = repeat("solver: demo\ntime: {steps: 1}\ndemo:\n  probes: [", "[0.5, 1], ", 100000,
                        "[0, 0]]\n");
  char *title = repeat("solver: demo\ntime: {steps: 1}\ntitle: \"", "0123456789", 100000, "\"\n");
  char *key = repeat("solver: demo\ntime: {steps: 1}\n", "k", 10000, ": 1\n");
  char *many = NULL;
  struct px_case *c = NULL;
  size_t count = 0, i, len = 0;
  const char *s;
  if (!probes || !title || !key) goto out;
  PX_CHECK_OK(ctx, load_n(probes, strlen(probes), NULL, 0, &c));
  if (c) {
    PX_CHECK_OK(ctx, px_case_count(c, "demo.probes", &count));
    PX_CHECK(count == 100001);
  }
  px_case_free(c);
  PX_CHECK_OK(ctx, load_n(title, strlen(title), NULL, 0, &c));
  if (c) {
    PX_CHECK_OK(ctx, px_case_get_string(c, "title", &s));
    PX_CHECK(strlen(s) == 1000000);
  }
  px_case_free(c);
  PX_CHECK_STATUS(ctx, load_n(key, strlen(key), NULL, 0, &c), PX_STATUS_CONFIG);
  PX_CHECK(strncmp(px_context_message(ctx),
                   "case.yaml:3:1: kkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkk"
                   "k...: unknown key (expected one of: solver, title, backend, time, output, "
                   "demo)",
                   200) == 0);
  /* 200000 copies of one known key: every repeat is a duplicate, in linear time */
  many = malloc(200000 * 12 + 64);
  if (!many) goto out;
  len = (size_t)sprintf(many, "solver: demo\ntime:\n");
  for (i = 0; i < 200000; ++i) len += (size_t)sprintf(many + len, "  steps: 1\n");
  PX_CHECK_STATUS(ctx, load_n(many, len, NULL, 0, &c), PX_STATUS_CONFIG);
  PX_CHECK(strncmp(px_context_message(ctx),
                   "case.yaml:4:3: time.steps: duplicate key (first given at line 3)\n"
                   "case.yaml:5:3: time.steps: duplicate key (first given at line 3)\n",
                   130) == 0);
  PX_CHECK(strstr(px_context_message(ctx), "\n(199979 more errors not shown)") != NULL);
  /* larger than the limit */
  {
    size_t big = PX_CASE_MAX_BYTES + 1;
    char *huge = malloc(big);
    if (huge) {
      memset(huge, ' ', big);
      PX_CHECK_STATUS(ctx, load_n(huge, big, NULL, 0, &c), PX_STATUS_CONFIG);
      PX_CHECK(strstr(px_context_message(ctx), "too large") != NULL);
      free(huge);
    }
  }
out:
  free(probes);
  free(title);
  free(key);
  free(many);
}

static void test_odd_scalars(void) {
  CHECK_MESSAGE(
      "solver: demo\n"
      "time: {steps: 0x10, dt: 1e400, end: 0x1p-3}\n"
      "backend: {threads: 99999999999999999999, device: 1_000, workgroup: ''}\n"
      "title: ~\n"
      "demo: {v_inf: [' 1', -.inf]}\n",
      "case.yaml:2:15: time.steps: expected an integer (got '0x10')\n"
      "case.yaml:2:25: time.dt: real number out of range (got '1e400')\n"
      "case.yaml:2:37: time.end: expected a real number (got '0x1p-3')\n"
      "case.yaml:3:20: backend.threads: integer out of range (got "
      "'99999999999999999999')\n"
      "case.yaml:3:50: backend.device: expected an integer (got '1_000')\n"
      "case.yaml:3:68: backend.workgroup: expected an integer (got '')\n"
      "case.yaml:4:8: title: expected a string (got null)\n"
      "case.yaml:5:16: demo.v_inf[0]: expected a real number (got ' 1')\n"
      "case.yaml:5:22: demo.v_inf[1]: expected a finite real number (got '-.inf')");
  CHECK_MESSAGE("",
                "case.yaml:1:1: missing required key 'solver' (solver to run)\n"
                "case.yaml:1:1: time: missing 'steps' or 'end' (give exactly one: the number "
                "of time steps, or the end time [s])");
  CHECK_MESSAGE("hello\n", "case.yaml:1:1: expected a map (got 'hello')");
  CHECK_MESSAGE("solver: demo\ntime: {steps: 1}\n\"\\0\": 1\n",
                "case.yaml:3:1: ?: unknown key (expected one of: solver, title, backend, time, "
                "output, demo)");
  CHECK_MESSAGE("solver: demo\ntime: {steps: 1}\ntitle: \"a\\0b\"\n",
                "case.yaml:3:8: title: a string must not contain NUL characters");
}

static void test_hostile_overrides(void) {
  const char *const ov[] = {"=1", "[0]=1", "a.b[9999999999]=1", ".a=1", "a.=1", "a[0=1"};
  char longpath[400];
  const char *const ov2[] = {longpath};
  size_t i;
  struct px_case *c = NULL;
  const char *msg, *line;
  size_t lines = 1;
  PX_CHECK_STATUS(ctx, load_n("solver: demo\ntime: {steps: 1}\n", 29, ov, 6, &c), PX_STATUS_CONFIG);
  msg = px_context_message(ctx);
  for (line = msg; *line; ++line) lines += *line == '\n';
  PX_CHECK_MSG(lines == 6, "%s", msg);
  PX_CHECK(strstr(msg, "--set a[0=1: malformed key path 'a[0'") != NULL);
  /* 100 segments: more than a path may have */
  for (i = 0; i < 100; ++i) memcpy(longpath + 2 * i, "a.", 2);
  memcpy(longpath + 198, "b=1", 4);
  PX_CHECK_STATUS(ctx, load_n("solver: demo\ntime: {steps: 1}\n", 29, ov2, 1, &c),
                  PX_STATUS_CONFIG);
  PX_CHECK(strstr(px_context_message(ctx), "malformed key path") != NULL);
}

/* Random edits of a valid case: insert, delete or replace bytes with YAML's
 * special characters. */
static void test_mutations_never_crash(void) {
  static const char base[] =
      "solver: demo\n"
      "title: \"run\"\n"
      "time: {dt: 1e-3, steps: 10}\n"
      "output:\n"
      "  every: 5\n"
      "demo:\n"
      "  v_inf: [1, 0]\n"
      "  bodies:\n"
      "    - type: circle\n"
      "      radius: 0.5\n"
      "      center: &c [0, 0]\n"
      "  probes: [*c, [1, 1]]\n";
  static const char special[] = ":-[]{},#&*!|>'\"%@` \t\n?x0.e";
  char text[sizeof base + 64];
  int k;
  for (k = 0; k < 3000; ++k) {
    size_t len = sizeof base - 1, edits = 1 + rng() % 4, e;
    memcpy(text, base, len);
    for (e = 0; e < edits; ++e) {
      size_t pos = rng() % len;
      unsigned long op = rng() % 3;
      char ch = special[rng() % (sizeof special - 1)];
      if (op == 0 && len + 1 < sizeof text) { /* insert */
        memmove(text + pos + 1, text + pos, len - pos);
        text[pos] = ch;
        ++len;
      } else if (op == 1 && len > 1) { /* delete */
        memmove(text + pos, text + pos + 1, len - pos - 1);
        --len;
      } else {
        text[pos] = ch;
      }
    }
    check_survives(__LINE__, text, len);
  }
}

int main(void) {
  if (px_context_create(&ctx) != PX_STATUS_OK) return EXIT_FAILURE;
  root = px_case_root_schema_build(sections, &storage);
  PX_CHECK(root != NULL);
  if (!root) return px_test_report("test_config_hostile");
  PX_CHECK_OK(ctx, px_case_schema_check(ctx, root));
  test_deep_nesting_is_refused();
  test_binary_junk();
  test_alias_bomb_is_bounded();
  test_huge_values();
  test_odd_scalars();
  test_hostile_overrides();
  test_mutations_never_crash();
  PX_CHECK(px_mem_current(ctx, "case") == 0);
  px_context_free(ctx);
  return px_test_report("test_config_hostile");
}
