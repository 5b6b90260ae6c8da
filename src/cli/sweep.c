/* partix sweep SWEEP.yaml: many runs of one case with other values of some
 * of its keys, each in its own folder, then one table of what they report.
 *
 *   case: naca0012_aoa5.yaml        the base case (relative to this file)
 *   dir: out/aoa                    the sweep folder, relative to the current
 *                                   folder as a case's output.dir (default
 *                                   out/<file name>)
 *   set: {time.end: 4}              overrides of every run (optional)
 *   grid:                           every combination of these values...
 *     vortex.bodies[0].angle: [0, 4, 8]
 *   runs:                           ...or a list of runs, each its overrides
 *     - {vortex.nu: 0.001}
 *   plot: {x: vortex.bodies[0].angle, y: C_y_mean}    (optional) sweep.png
 *
 * Each run is `partix run CASE --out DIR/NAME --set KEY=VALUE...` in a child
 * process (at most --jobs J at a time), NAME made of the varied keys' last
 * names and values ("angle-4"). Every run's case is loaded and validated
 * before any runs. A run that fails is recorded with its error and the others
 * go on. Running the sweep again skips the runs whose summary.json says
 * "finished" and resumes the others that have a checkpoint, when they were
 * made with the same settings (DIR/.NAME.fingerprint, px_sweep_decide in sweep_run.c); a
 * folder made with others is left alone and its run failed. The table is
 * DIR/sweep.csv and DIR/sweep.json: the varied values, status, wall time and
 * every quantity of each run's summary.json. Exit status: 0 when every run
 * finished, 1 when some failed, 2 for a sweep file that cannot run.
 * Started by mpirun (K >= 2 ranks), rank 0 hands the runs out one at a time
 * to ranks 1..K-1, which run them in their own process (px_sweep_mpi,
 * sweep_run.c). */
#include <libfyaml.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/sweep.h"
#include "core/text.h"
#include "partix/partix.h"

#ifdef PX_HAVE_MPI
#include <mpi.h>
#endif

/* Where a node starts in the sweep file: its scalar's token, or that of a
 * map's first key or a list's first item (libfyaml keeps tokens for
 * scalars); for an empty map or list ({}, []), where its key is. NULL when
 * there is none. */
static const struct fy_mark *px_sweep_mark(struct fy_node *n) {
  void *it = NULL;
  struct fy_token *tok;
  struct fy_node_pair *p;
  struct fy_node *parent;
  if (!n) return NULL;
  if ((fy_node_is_mapping(n) && fy_node_mapping_item_count(n) == 0) ||
      (fy_node_is_sequence(n) && fy_node_sequence_item_count(n) == 0)) {
    parent = fy_node_get_parent(n);
    while (parent && fy_node_is_mapping(parent) &&
           (p = fy_node_mapping_iterate(parent, &it)) != NULL)
      if (fy_node_pair_value(p) == n) return px_sweep_mark(fy_node_pair_key(p));
    return NULL;
  }
  if (fy_node_is_scalar(n)) {
    tok = fy_node_get_scalar_token(n);
    return tok ? fy_token_start_mark(tok) : NULL;
  }
  if (fy_node_is_mapping(n)) {
    p = fy_node_mapping_iterate(n, &it);
    return p ? px_sweep_mark(fy_node_pair_key(p)) : NULL;
  }
  if (fy_node_is_sequence(n)) return px_sweep_mark(fy_node_sequence_iterate(n, &it));
  return NULL;
}

/* 1 on the ranks of an MPI sweep but the first: they read and check the
 * sweep file as rank 0 does, silently. */
static int px_sweep_quiet;

/* "FILE:LINE:COL: message" for a node of the sweep file; returns 2. */
static int px_sweep_fail(const struct px_sweep *s, struct fy_node *n, const char *fmt, ...)
    PX_PRINTF(3, 4);
static int px_sweep_fail(const struct px_sweep *s, struct fy_node *n, const char *fmt, ...) {
  va_list ap;
  const struct fy_mark *m = px_sweep_mark(n);
  if (px_sweep_quiet) return PX_CLI_EXIT_USAGE;
  if (m)
    fprintf(stderr, "%s:%d:%d: ", s->file, m->line + 1, m->column + 1);
  else
    fprintf(stderr, "%s: ", s->file);
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
  return PX_CLI_EXIT_USAGE;
}

/* A run's folder name: the varied keys' last names and values
 * ("angle-4_nu-0.001"), characters outside [A-Za-z0-9._-] as '-'. When that
 * replaced a character, values that differ only there ("a/b", "a-b", "a:b")
 * would share a folder: such a name ends in a hash of what it was made of
 * ("title-a-b-1f0c9a3e"), so it depends on the run's own values only, not on
 * the order of the runs. The run's number when the name would be too long
 * or empty. Names that still repeat are refused (px_sweep_load). */
static void px_sweep_name(struct px_sweep *s, size_t r) {
  struct px_sweep_run *run = &s->runs[r];
  size_t k, used = 0;
  int replaced = 0;
  char *p;
  run->name[0] = '\0';
  for (k = 0; k < s->nkeys; ++k) {
    const char *last = strrchr(s->key[k], '.');
    char key[64];
    int n;
    if (!run->value[k]) continue; /* a run of a list that keeps the case's value */
    snprintf(key, sizeof key, "%s", last ? last + 1 : s->key[k]);
    if ((p = strchr(key, '[')) != NULL) *p = '\0';
    char value[96];
    const char *v;
    size_t m = 0;
    /* a list value "[1, 0.1]" as "1-0.1" */
    for (v = run->value[k]; *v && m + 1 < sizeof value; ++v)
      if (*v != '[' && *v != ']' && *v != ' ') value[m++] = *v == ',' ? '-' : *v;
    value[m] = '\0';
    n = snprintf(run->name + used, sizeof run->name - used, "%s%s-%s", used ? "_" : "", key, value);
    if (n < 0 || (size_t)n >= sizeof run->name - used) {
      run->name[0] = '\0';
      break;
    }
    used += (size_t)n;
  }
  if (run->name[0]) {
    /* FNV-1a from 1469598103934665603, not its offset basis: the seed the
       names' suffixes were first made with */
    const uint64_t h = px_text_fnv1a(1469598103934665603ULL, run->name, strlen(run->name));
    for (p = run->name; *p; ++p)
      if (!((*p >= 'A' && *p <= 'Z') || (*p >= 'a' && *p <= 'z') || (*p >= '0' && *p <= '9') ||
            *p == '.' || *p == '-' || *p == '_')) {
        *p = '-';
        replaced = 1;
      }
    if (replaced && used + 9 < sizeof run->name)
      snprintf(run->name + used, sizeof run->name - used, "-%08x", (unsigned)(h >> 32));
    else if (replaced)
      run->name[0] = '\0';
  }
  if (!run->name[0] || run->name[0] == '.') snprintf(run->name, sizeof run->name, "run-%04zu", r);
}

/* The overrides of run r: the sweep's `set`, then its own values. */
static int px_sweep_overrides(struct px_sweep *s, size_t r) {
  struct px_sweep_run *run = &s->runs[r];
  size_t k;
  for (k = 0; k < s->nset + s->nkeys; ++k) {
    const char *key = k < s->nset ? s->set_key[k] : s->key[k - s->nset];
    const char *value = k < s->nset ? s->set_value[k] : run->value[k - s->nset];
    size_t len;
    if (!value) continue;
    len = strlen(key) + strlen(value) + 2;
    run->overrides[run->noverrides] = malloc(len);
    if (!run->overrides[run->noverrides]) return -1;
    snprintf(run->overrides[run->noverrides++], len, "%s=%s", key, value);
  }
  return 0;
}

/* grid: the varied keys, and the number of runs (every combination). */
static int px_sweep_grid_keys(struct px_sweep *s, struct fy_node *grid, size_t *ptotal) {
  struct fy_node_pair *p;
  void *it = NULL;
  size_t total = 1;
  if (!fy_node_is_mapping(grid) || fy_node_mapping_item_count(grid) < 1)
    return px_sweep_fail(s, grid, "grid: a map of case keys to lists of values");
  for (; (p = fy_node_mapping_iterate(grid, &it)) != NULL;) {
    struct fy_node *v = fy_node_pair_value(p);
    if (s->nkeys == PX_SWEEP_MAX_KEYS)
      return px_sweep_fail(s, fy_node_pair_key(p), "grid: at most %d keys", PX_SWEEP_MAX_KEYS);
    s->key[s->nkeys] = px_sweep_scalar(fy_node_pair_key(p));
    if (!v || !fy_node_is_sequence(v) || fy_node_sequence_item_count(v) < 1)
      return px_sweep_fail(s, v ? v : fy_node_pair_key(p), "grid: %s: a list of values",
                           s->key[s->nkeys] ? s->key[s->nkeys] : "?");
    total *= (size_t)fy_node_sequence_item_count(v);
    if (total > PX_SWEEP_MAX_RUNS)
      return px_sweep_fail(s, grid, "grid: more than %d runs", PX_SWEEP_MAX_RUNS);
    ++s->nkeys;
  }
  *ptotal = total;
  return 0;
}

/* runs: the varied keys (every key some run names, in order of appearance)
 * and the number of runs. */
static int px_sweep_list_keys(struct px_sweep *s, struct fy_node *list, size_t *ptotal) {
  struct fy_node_pair *p;
  void *it = NULL;
  size_t total, r, k;
  if (!fy_node_is_sequence(list) || fy_node_sequence_item_count(list) < 1)
    return px_sweep_fail(s, list, "runs: a list of maps of case keys to values");
  total = (size_t)fy_node_sequence_item_count(list);
  if (total > PX_SWEEP_MAX_RUNS)
    return px_sweep_fail(s, list, "runs: more than %d runs", PX_SWEEP_MAX_RUNS);
  for (r = 0; r < total; ++r) {
    struct fy_node *m = fy_node_sequence_get_by_index(list, (int)r);
    if (!m || !fy_node_is_mapping(m))
      return px_sweep_fail(s, m ? m : list, "runs: each run is a map of case keys to values");
    for (it = NULL; (p = fy_node_mapping_iterate(m, &it)) != NULL;) {
      const char *key = px_sweep_scalar(fy_node_pair_key(p));
      if (!key || !px_sweep_scalar(fy_node_pair_value(p)))
        return px_sweep_fail(s, fy_node_pair_value(p), "runs: each value is a single value");
      for (k = 0; k < s->nkeys && strcmp(s->key[k], key) != 0; ++k) {
      }
      if (k == s->nkeys) {
        if (s->nkeys == PX_SWEEP_MAX_KEYS)
          return px_sweep_fail(s, fy_node_pair_key(p), "runs: at most %d keys", PX_SWEEP_MAX_KEYS);
        s->key[s->nkeys++] = key;
      }
    }
  }
  *ptotal = total;
  return 0;
}

/* Read the sweep file: keys, values, runs. 0 or an exit code. */
static int px_sweep_load(struct px_sweep *s) {
  struct fy_node *root, *n, *grid, *list;
  struct fy_node_pair *p;
  void *it = NULL;
  const char *c;
  char dir[4096];
  size_t k, r, total = 1;
  int code;
  if (!px_file_exists(s->file)) {
    fprintf(stderr, "partix sweep: %s: no such file\n", s->file);
    return PX_CLI_EXIT_USAGE;
  }
  s->doc = fy_document_build_from_file(NULL, s->file);
  if (!s->doc) {
    fprintf(stderr, "%s: cannot read the sweep file: not valid YAML (see above)\n", s->file);
    return PX_CLI_EXIT_USAGE;
  }
  root = fy_document_root(s->doc);
  if (!root || !fy_node_is_mapping(root))
    return px_sweep_fail(s, root, "a sweep file is a map (case, dir, set, grid or runs, plot)");
  while ((p = fy_node_mapping_iterate(root, &it)) != NULL) {
    const char *key = px_sweep_scalar(fy_node_pair_key(p));
    static const char *const known[] = {"case", "dir", "set", "grid", "runs", "plot"};
    for (k = 0; k < 6 && !(key && strcmp(key, known[k]) == 0); ++k) {
    }
    if (k == 6)
      return px_sweep_fail(s, fy_node_pair_key(p),
                           "unknown key '%s' (a sweep has case, dir, set, grid or runs, plot)",
                           key ? key : "?");
  }
  /* the base case and the folder, relative to the sweep file */
  snprintf(dir, sizeof dir, "%s", s->file);
  if (strrchr(dir, '/'))
    strrchr(dir, '/')[1] = '\0';
  else
    dir[0] = '\0';
  n = fy_node_mapping_lookup_by_string(root, "case", 4);
  c = px_sweep_scalar(n);
  if (!c || !c[0]) return px_sweep_fail(s, n ? n : root, "case: the base case file is required");
  snprintf(s->base, sizeof s->base, "%s%s", c[0] == '/' ? "" : dir, c);
  if (!px_file_exists(s->base)) return px_sweep_fail(s, n, "case: no file '%s'", s->base);
  n = fy_node_mapping_lookup_by_string(root, "dir", 3);
  c = px_sweep_scalar(n);
  if (n && (!c || !c[0])) return px_sweep_fail(s, n, "dir: a folder name");
  if (c) {
    /* like a case's output.dir: relative to the current folder */
    snprintf(s->dir, sizeof s->dir, "%s", c);
  } else {
    const char *b = strrchr(s->file, '/') ? strrchr(s->file, '/') + 1 : s->file;
    snprintf(s->dir, sizeof s->dir, "out/%.*s", (int)strcspn(b, "."), b);
  }
  /* set: overrides of every run */
  n = fy_node_mapping_lookup_by_string(root, "set", 3);
  if (n && !fy_node_is_mapping(n)) return px_sweep_fail(s, n, "set: a map of case keys to values");
  for (it = NULL; n && (p = fy_node_mapping_iterate(n, &it)) != NULL;) {
    if (s->nset == PX_SWEEP_MAX_KEYS)
      return px_sweep_fail(s, fy_node_pair_key(p), "set: at most %d keys", PX_SWEEP_MAX_KEYS);
    s->set_key[s->nset] = px_sweep_scalar(fy_node_pair_key(p));
    s->set_value[s->nset] = px_sweep_scalar(fy_node_pair_value(p));
    if (!s->set_key[s->nset] || !s->set_value[s->nset])
      return px_sweep_fail(s, fy_node_pair_value(p), "set: each value is a single value");
    ++s->nset;
  }
  /* grid or runs */
  grid = fy_node_mapping_lookup_by_string(root, "grid", 4);
  list = fy_node_mapping_lookup_by_string(root, "runs", 4);
  if (!grid == !list)
    return px_sweep_fail(s,
                         grid   ? grid
                         : list ? list
                                : root,
                         "give either grid (every combination) or runs (a list)");
  code = grid ? px_sweep_grid_keys(s, grid, &total) : px_sweep_list_keys(s, list, &total);
  if (code) return code;
  s->runs = calloc(total, sizeof *s->runs);
  if (!s->runs) return PX_CLI_EXIT_FAILURE;
  s->nruns = total;
  for (r = 0; r < total; ++r) {
    struct px_sweep_run *run = &s->runs[r];
    if (grid) {
      size_t rest = r;
      /* the last key varies fastest */
      for (k = s->nkeys; k-- > 0;) {
        struct fy_node *v = fy_node_mapping_lookup_by_string(grid, s->key[k], FY_NT);
        const size_t m = (size_t)fy_node_sequence_item_count(v);
        struct fy_node *item = fy_node_sequence_get_by_index(v, (int)(rest % m));
        run->value[k] = px_sweep_scalar(item);
        if (!run->value[k]) return px_sweep_fail(s, item, "grid: each value is a single value");
        rest /= m;
      }
    } else {
      struct fy_node *m = fy_node_sequence_get_by_index(list, (int)r);
      for (k = 0; k < s->nkeys; ++k)
        run->value[k] = px_sweep_scalar(fy_node_mapping_lookup_by_string(m, s->key[k], FY_NT));
    }
    px_sweep_name(s, r);
    if (px_sweep_overrides(s, r) != 0) return PX_CLI_EXIT_FAILURE;
    snprintf(run->status, sizeof run->status, "not run");
    run->exit = -1;
  }
  /* two runs in one folder would overwrite each other's results */
  for (r = 1; r < s->nruns; ++r)
    for (k = 0; k < r; ++k)
      if (strcmp(s->runs[k].name, s->runs[r].name) == 0)
        return px_sweep_fail(s, grid ? grid : fy_node_sequence_get_by_index(list, (int)r),
                             "%s %zu and %zu would share the folder %s/%s: their values are the "
                             "same, or differ only in spaces or brackets; give each run values "
                             "of its own",
                             grid ? "grid: runs" : "runs: runs", k + 1, r + 1, s->dir,
                             s->runs[r].name);
  /* plot: x a varied key, y a summary quantity */
  n = fy_node_mapping_lookup_by_string(root, "plot", 4);
  if (n) {
    s->plot_x = px_sweep_scalar(fy_node_mapping_lookup_by_string(n, "x", 1));
    s->plot_y = px_sweep_scalar(fy_node_mapping_lookup_by_string(n, "y", 1));
    if (!fy_node_is_mapping(n) || !s->plot_x || !s->plot_y)
      return px_sweep_fail(s, n, "plot: {x: a varied key, y: a quantity of summary.json}");
    for (k = 0; k < s->nkeys && strcmp(s->key[k], s->plot_x) != 0; ++k) {
    }
    if (k == s->nkeys)
      return px_sweep_fail(s, n, "plot: x = %s is not a key the sweep varies", s->plot_x);
  }
  return 0;
}

/* The value of `key` ("vortex.bodies[0].angle") in resolved case text, as
 * `--set` takes it ("4", "[1, 0.1]"); owned, NULL when the text has none. */
static char *px_sweep_case_value(const char *text, const char *key) {
  char path[512];
  size_t m = 0;
  const char *k;
  struct fy_document *d;
  struct fy_node *n;
  char *out = NULL;
  path[m++] = '/';
  for (k = key; *k && m + 2 < sizeof path; ++k)
    if (*k == '.' || *k == '[')
      path[m++] = '/';
    else if (*k != ']')
      path[m++] = *k;
  path[m] = '\0';
  d = fy_document_build_from_string(NULL, text, FY_NT);
  n = d ? fy_node_by_path(fy_document_root(d), path, FY_NT, FYNWF_DONT_FOLLOW) : NULL;
  if (n && fy_node_is_scalar(n)) {
    out = strdup(fy_node_get_scalar0(n));
  } else if (n) {
    out = fy_emit_node_to_string(n, FYECF_MODE_FLOW_ONELINE | FYECF_WIDTH_INF);
    if (out) out[strcspn(out, "\n")] = '\0';
  }
  if (d) fy_document_destroy(d);
  return out;
}

/* Every run's case loads and validates (keys, values, ranges) before any
 * runs: a misspelt key fails the sweep, not each of its runs. */
int px_sweep_check(struct px_sweep *s, struct px_context *ctx) {
  size_t r;
  for (r = 0; r < s->nruns; ++r) {
    struct px_case *c = NULL;
    enum px_status st = px_case_load(ctx, s->base, (const char *const *)s->runs[r].overrides,
                                     s->runs[r].noverrides, &c);
    struct px_sweep_run *run = &s->runs[r];
    size_t k;
    run->fingerprint = px_case_hash(c);
    /* the table shows the value a run used, also of a key it leaves out */
    for (k = 0; c && k < s->nkeys; ++k)
      if (!run->value[k])
        run->value[k] = run->taken[k] = px_sweep_case_value(px_case_resolved_text(c), s->key[k]);
    px_case_free(c);
    if (st != PX_STATUS_OK) {
      if (!px_sweep_quiet)
        fprintf(stderr, "%s: run %s: %s\n", s->file, s->runs[r].name, px_context_message(ctx));
      return PX_CLI_EXIT_USAGE;
    }
  }
  return 0;
}

static void px_sweep_help(void) {
  printf(
      "usage: partix sweep SWEEP.yaml [--jobs J] [--dry-run]\n\n"
      "Runs one case many times with other values of some of its keys, each run in its\n"
      "own folder, at most J at a time (default 1), then writes DIR/sweep.csv and\n"
      "DIR/sweep.json (the values, status, wall time and every quantity of each run's\n"
      "summary.json) and, with `plot:`, DIR/sweep.png. Every run's case is validated\n"
      "first. Running it again skips finished runs and resumes interrupted ones; a run\n"
      "folder made with other settings (the case or the overrides changed) is left\n"
      "alone and its run recorded as failed.\n"
      "Under mpirun -np K (K >= 2), rank 0 hands the runs to the other ranks instead.\n"
      "--dry-run lists the runs and their folders without running them. The sweep\n"
      "file (docs/sweeps.md):\n\n"
      "  case: CASE.yaml               the base case, relative to the sweep file\n"
      "  dir: out/NAME                 the sweep folder (default out/<file name>)\n"
      "  set: {KEY: VALUE, ...}        overrides of every run\n"
      "  grid: {KEY: [V1, V2], ...}    every combination, or\n"
      "  runs: [{KEY: VALUE, ...}, ...] a list of runs\n"
      "  plot: {x: KEY, y: QUANTITY}   a summary quantity against a varied key\n\n"
      "Exit status: 0 every run finished, 1 some failed (see sweep.csv), 2 the sweep\n"
      "file or a run's case is wrong.\n");
}

int px_cli_sweep(struct px_cli *cli) {
  struct px_sweep s;
  struct px_context *ctx = NULL;
  long jobs = 1;
  int dry = 0, code = 0, i, mpi = 0, rank = 0;
#ifdef PX_HAVE_MPI
  int size = 1;
#endif
  size_t r;
  if (px_cli_wants_help(cli)) {
    px_sweep_help();
    return PX_CLI_EXIT_OK;
  }
  memset(&s, 0, sizeof s);
  for (i = 0; i < cli->argc; ++i) {
    const char *a = cli->argv[i];
    if (strcmp(a, "--jobs") == 0 || strcmp(a, "-j") == 0) {
      char *end = NULL;
      jobs = i + 1 < cli->argc ? strtol(cli->argv[++i], &end, 10) : 0;
      if (!end || *end || jobs < 1 || jobs > PX_SWEEP_MAX_JOBS) {
        fprintf(stderr, "partix sweep: --jobs takes a number from 1 to %d\n", PX_SWEEP_MAX_JOBS);
        return PX_CLI_EXIT_USAGE;
      }
    } else if (strcmp(a, "--dry-run") == 0) {
      dry = 1;
    } else if (strcmp(a, "-q") == 0 || strcmp(a, "--quiet") == 0) {
      cli->log_level = PX_LOG_LEVEL_WARN;
    } else if (strcmp(a, "-v") == 0 || strcmp(a, "--verbose") == 0) {
      if (cli->log_level < PX_LOG_LEVEL_TRACE) cli->log_level++;
    } else if (a[0] == '-' && a[1]) {
      fprintf(stderr, "partix sweep: unknown option '%s' (see partix sweep --help)\n", a);
      return PX_CLI_EXIT_USAGE;
    } else if (s.file) {
      fprintf(stderr, "partix sweep: one sweep file at a time ('%s' and '%s')\n", s.file, a);
      return PX_CLI_EXIT_USAGE;
    } else {
      s.file = a;
    }
  }
  if (!s.file) {
    fprintf(stderr, "partix sweep: no sweep file given (see partix sweep --help)\n");
    return PX_CLI_EXIT_USAGE;
  }
  if (px_cli_launch_ranks() > 1) {
#ifdef PX_HAVE_MPI
    mpi = 1;
    MPI_Init(NULL, NULL);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    px_sweep_quiet = rank != 0;
    if (size < 2) {
      fprintf(stderr,
              "partix sweep: an MPI sweep needs 2 ranks or more (rank 0 hands out "
              "the runs)\n");
      MPI_Finalize();
      return PX_CLI_EXIT_USAGE;
    }
#else
    fprintf(stderr,
            "partix sweep: started as one of %ld MPI ranks, but this build has no MPI "
            "(configure with -DPX_WITH_MPI=ON); run it without mpirun, with --jobs; nothing was "
            "written.\n",
            px_cli_launch_ranks());
    return PX_CLI_EXIT_USAGE;
#endif
  }
  ctx = px_cli_context(cli);
  if (!ctx) return PX_CLI_EXIT_FAILURE;
  code = px_sweep_load(&s);
  if (!code) code = px_sweep_check(&s, ctx);
  if (code) goto done;
  if (dry) {
    for (r = 0; r < s.nruns && rank == 0; ++r) {
      size_t k;
      printf("%s/%s:", s.dir, s.runs[r].name);
      for (k = 0; k < s.runs[r].noverrides; ++k) printf(" --set %s", s.runs[r].overrides[k]);
      printf("\n");
    }
    goto done;
  }
  if (mpi) {
#ifdef PX_HAVE_MPI
    int ok = rank != 0 || px_file_mkdirs(ctx, s.dir) == PX_STATUS_OK, failed = 0;
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (!ok) {
      if (rank == 0) fprintf(stderr, "partix sweep: %s\n", px_context_message(ctx));
      code = PX_CLI_EXIT_FAILURE;
      goto done;
    }
    px_sweep_mpi(&s, cli, ctx, rank, size, &failed);
    if (rank == 0) code = px_sweep_finish(&s, ctx, failed);
#endif
  } else {
    code = px_sweep_execute(&s, cli, ctx, jobs);
  }
done:
  for (r = 0; r < s.nruns; ++r) {
    size_t k;
    for (k = 0; k < s.runs[r].noverrides; ++k) free(s.runs[r].overrides[k]);
    for (k = 0; k < s.nkeys; ++k) free(s.runs[r].taken[k]);
  }
  free(s.runs);
  if (s.doc) fy_document_destroy(s.doc);
  px_context_free(ctx);
#ifdef PX_HAVE_MPI
  if (mpi) MPI_Finalize();
#endif
  return code;
}
