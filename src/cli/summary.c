/* partix summary RUN_DIR...: the summary.json of runs as a table. */
#include <libfyaml.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli/cli.h"

#define PX_CLI_SUMMARY_MAX_RUNS 64
#define PX_CLI_SUMMARY_MAX_ROWS 512
#define PX_CLI_SUMMARY_CELL 64

struct px_cli_run_summary {
  const char *arg;            /* borrowed: the run folder or file named */
  struct fy_document *doc;    /* owned */
  struct fy_node *quantities; /* in doc */
};

/* Six significant digits for a real in the table ("0.000697891"); other text
 * as it is. */
static void px_cli_summary_short(char *buf, size_t size) {
  char *end = NULL;
  double v = strtod(buf, &end);
  if (end && end != buf && *end == '\0' && strpbrk(buf, ".eE")) snprintf(buf, size, "%.6g", v);
}

void px_cli_summary_text(struct fy_node *n, char *buf, size_t size, int brief, const char *none) {
  size_t len = 0, used = 0;
  const char *s;
  buf[0] = '\0';
  if (!n || fy_node_is_null(n)) {
    snprintf(buf, size, "%s", none);
    return;
  }
  if (fy_node_is_scalar(n)) {
    s = fy_node_get_scalar(n, &len);
    if (!s || (len == 4 && strncmp(s, "null", 4) == 0))
      snprintf(buf, size, "%s", none);
    else
      snprintf(buf, size, "%.*s", (int)len, s);
    if (brief) px_cli_summary_short(buf, size);
    return;
  }
  if (fy_node_is_sequence(n)) {
    void *iter = NULL;
    struct fy_node *item;
    used = (size_t)snprintf(buf, size, "[");
    while ((item = fy_node_sequence_iterate(n, &iter)) != NULL && used + 2 < size) {
      char one[PX_CLI_SUMMARY_CELL];
      px_cli_summary_text(item, one, sizeof one, brief, none);
      used += (size_t)snprintf(buf + used, size - used, "%s%s", used > 1 ? ", " : "", one);
    }
    if (used + 1 < size) snprintf(buf + used, size - used, "]");
    return;
  }
  snprintf(buf, size, "{...}");
}

struct fy_node *px_cli_json_get(struct fy_node *map, const char *key) {
  return map && fy_node_is_mapping(map) ? fy_node_mapping_lookup_by_string(map, key, strlen(key))
                                        : NULL;
}

struct fy_node *px_cli_summary_value(struct fy_document *d, const char *name) {
  struct fy_node *q =
      px_cli_json_get(px_cli_json_get(d ? fy_document_root(d) : NULL, "quantities"), name);
  return px_cli_json_get(q, "value");
}

/* libfyaml's report of a file that is no JSON: dropped, the caller says it
 * in one line. */
static void px_cli_summary_quiet(struct fy_diag *diag, void *user, const char *buf, size_t len) {
  (void)diag;
  (void)user;
  (void)buf;
  (void)len;
}

/* 1 when the file starts with a NUL byte in its first 4 KiB: binary (a
 * picture), which the JSON parser is not given (libfyaml 0.7 may loop on
 * invalid text). */
static int px_cli_summary_binary(const char *path) {
  char buf[4096];
  size_t n;
  FILE *f = fopen(path, "rb");
  if (!f) return 0;
  n = fread(buf, 1, sizeof buf, f);
  fclose(f);
  return n > 0 && memchr(buf, '\0', n) != NULL;
}

/* Open RUN_DIR/summary.json (or the file itself). 0 on success. */
static int px_cli_summary_open(struct px_cli_run_summary *r) {
  char path[4096];
  struct stat st;
  struct fy_node *root;
  struct fy_parse_cfg cfg;
  struct fy_diag_cfg dcfg;
  if (stat(r->arg, &st) == 0 && S_ISDIR(st.st_mode))
    snprintf(path, sizeof path, "%s/summary.json", r->arg);
  else
    snprintf(path, sizeof path, "%s", r->arg);
  if (stat(path, &st) != 0) {
    char table[4200];
    snprintf(table, sizeof table, "%s/sweep.csv", r->arg);
    if (stat(table, &st) == 0)
      /* a sweep's (or part3d's) folder: its table, and its runs' folders */
      fprintf(stderr,
              "partix summary: %s: a sweep's folder, not a run's: its table is %s; "
              "`partix summary %s/*/` shows its runs\n",
              r->arg, table, r->arg);
    else
      fprintf(stderr, "partix summary: %s: no summary.json (is it a run folder?)\n", r->arg);
    return -1;
  }
  /* quiet: a file that is no JSON at all (sweep.csv of a sweep folder
     named by a wildcard) gets the one line below, not the parser's report */
  fy_diag_cfg_default(&dcfg);
  dcfg.fp = NULL;
  dcfg.output_fn = px_cli_summary_quiet;
  memset(&cfg, 0, sizeof cfg);
  cfg.flags = FYPCF_QUIET;
  cfg.diag = px_cli_summary_binary(path) ? NULL : fy_diag_create(&dcfg);
  r->doc = cfg.diag ? fy_document_build_from_file(&cfg, path) : NULL;
  if (cfg.diag) fy_diag_destroy(cfg.diag);
  root = r->doc ? fy_document_root(r->doc) : NULL;
  if (!root || !fy_node_is_mapping(root) || !px_cli_json_get(root, "solver")) {
    fprintf(stderr, "partix summary: %s: not a partix summary.json\n", path);
    return -1;
  }
  r->quantities = px_cli_json_get(root, "quantities");
  return 0;
}

static void px_cli_summary_help(void) {
  printf(
      "usage: partix summary [--csv] RUN_DIR...\n\n"
      "Prints what the runs report (RUN_DIR/summary.json, written at every checkpoint and\n"
      "at the end): status, steps, simulated and wall time, then the solver's quantities\n"
      "with units, one column per run. --csv prints `run,quantity,value,unit` rows for\n"
      "scripts instead.\n");
}

/* The run's header rows: name -> path in the document. */
static const struct {
  const char *label, *key, *unit;
} px_cli_summary_head[] = {
    {"solver", "solver", ""},       {"status", "status", ""}, {"step", "step", "-"},
    {"steps", "steps", "-"},        {"time", "time_s", "s"},  {"wall time", "wall_time_s", "s"},
    {"case hash", "case_hash", ""},
};

int px_cli_summary(struct px_cli *cli) {
  struct px_cli_run_summary runs[PX_CLI_SUMMARY_MAX_RUNS];
  const char *rows[PX_CLI_SUMMARY_MAX_ROWS], *units[PX_CLI_SUMMARY_MAX_ROWS];
  size_t nruns = 0, nrows = 0, i, j, k, w0 = 8, wcol[PX_CLI_SUMMARY_MAX_RUNS];
  int csv = 0, code = PX_CLI_EXIT_OK;
  char cell[PX_CLI_SUMMARY_CELL * 4];
  if (px_cli_wants_help(cli)) {
    px_cli_summary_help();
    return PX_CLI_EXIT_OK;
  }
  memset(runs, 0, sizeof runs);
  for (i = 0; i < (size_t)cli->argc; ++i) {
    const char *a = cli->argv[i];
    if (strcmp(a, "--csv") == 0) {
      csv = 1;
    } else if (a[0] == '-' && a[1] != '\0') {
      fprintf(stderr, "partix summary: unknown option '%s' (see partix summary --help)\n", a);
      return PX_CLI_EXIT_USAGE;
    } else if (nruns == PX_CLI_SUMMARY_MAX_RUNS) {
      fprintf(stderr, "partix summary: at most %d runs at a time\n", PX_CLI_SUMMARY_MAX_RUNS);
      return PX_CLI_EXIT_USAGE;
    } else {
      runs[nruns++].arg = a;
    }
  }
  if (!nruns) {
    fprintf(stderr, "partix summary: no run folder given (see partix summary --help)\n");
    return PX_CLI_EXIT_USAGE;
  }
  for (i = 0; i < nruns; ++i)
    if (px_cli_summary_open(&runs[i]) != 0) code = PX_CLI_EXIT_USAGE;
  if (code != PX_CLI_EXIT_OK) goto done;

  /* the quantities of all runs, in the order they first appear */
  for (i = 0; i < nruns; ++i) {
    void *iter = NULL;
    struct fy_node_pair *p;
    if (!runs[i].quantities || !fy_node_is_mapping(runs[i].quantities)) continue;
    while ((p = fy_node_mapping_iterate(runs[i].quantities, &iter)) != NULL) {
      const char *name = fy_node_get_scalar0(fy_node_pair_key(p));
      struct fy_node *unit = px_cli_json_get(fy_node_pair_value(p), "unit");
      if (!name) continue;
      for (j = 0; j < nrows; ++j)
        if (strcmp(rows[j], name) == 0) break;
      if (j < nrows || nrows == PX_CLI_SUMMARY_MAX_ROWS) continue;
      rows[nrows] = name;
      units[nrows] = unit ? fy_node_get_scalar0(unit) : NULL;
      ++nrows;
    }
  }

  if (csv) {
    printf("run,quantity,value,unit\n");
    for (i = 0; i < nruns; ++i) {
      struct fy_node *root = fy_document_root(runs[i].doc);
      for (k = 0; k < sizeof px_cli_summary_head / sizeof px_cli_summary_head[0]; ++k) {
        px_cli_summary_text(px_cli_json_get(root, px_cli_summary_head[k].key), cell, sizeof cell, 0,
                            "-");
        printf("\"%s\",%s,\"%s\",%s\n", runs[i].arg, px_cli_summary_head[k].key, cell,
               px_cli_summary_head[k].unit);
      }
      for (j = 0; j < nrows; ++j) {
        struct fy_node *q = px_cli_json_get(runs[i].quantities, rows[j]);
        if (!q) continue;
        px_cli_summary_text(px_cli_json_get(q, "value"), cell, sizeof cell, 0, "-");
        printf("\"%s\",%s,\"%s\",%s\n", runs[i].arg, rows[j], cell, units[j] ? units[j] : "");
      }
    }
    goto done;
  }

  /* a table: one row per quantity, one column per run */
  w0 = 14; /* "wall time [s]" */
  for (j = 0; j < nrows; ++j) {
    size_t w = strlen(rows[j]) + (units[j] && units[j][0] ? strlen(units[j]) + 3 : 0);
    if (w > w0) w0 = w;
  }
  for (i = 0; i < nruns; ++i) {
    struct fy_node *root = fy_document_root(runs[i].doc);
    wcol[i] = strlen(runs[i].arg);
    for (k = 0; k < sizeof px_cli_summary_head / sizeof px_cli_summary_head[0]; ++k) {
      px_cli_summary_text(px_cli_json_get(root, px_cli_summary_head[k].key), cell, sizeof cell, 1,
                          "-");
      if (strlen(cell) > wcol[i]) wcol[i] = strlen(cell);
    }
    for (j = 0; j < nrows; ++j) {
      px_cli_summary_text(px_cli_json_get(px_cli_json_get(runs[i].quantities, rows[j]), "value"),
                          cell, sizeof cell, 1, "-");
      if (strlen(cell) > wcol[i]) wcol[i] = strlen(cell);
    }
  }
  printf("%-*s", (int)w0, "");
  for (i = 0; i < nruns; ++i) printf("  %-*s", (int)wcol[i], runs[i].arg);
  printf("\n");
  for (k = 0; k < sizeof px_cli_summary_head / sizeof px_cli_summary_head[0]; ++k) {
    char label[128];
    snprintf(label, sizeof label, "%s%s%s%s", px_cli_summary_head[k].label,
             px_cli_summary_head[k].unit[0] && strcmp(px_cli_summary_head[k].unit, "-") ? " [" : "",
             strcmp(px_cli_summary_head[k].unit, "-") ? px_cli_summary_head[k].unit : "",
             px_cli_summary_head[k].unit[0] && strcmp(px_cli_summary_head[k].unit, "-") ? "]" : "");
    printf("%-*s", (int)w0, label);
    for (i = 0; i < nruns; ++i) {
      px_cli_summary_text(
          px_cli_json_get(fy_document_root(runs[i].doc), px_cli_summary_head[k].key), cell,
          sizeof cell, 1, "-");
      printf("  %-*s", (int)wcol[i], cell);
    }
    printf("\n");
  }
  for (j = 0; j < nrows; ++j) {
    char label[256];
    if (units[j] && units[j][0])
      snprintf(label, sizeof label, "%s [%s]", rows[j], units[j]);
    else
      snprintf(label, sizeof label, "%s", rows[j]);
    printf("%-*s", (int)w0, label);
    for (i = 0; i < nruns; ++i) {
      px_cli_summary_text(px_cli_json_get(px_cli_json_get(runs[i].quantities, rows[j]), "value"),
                          cell, sizeof cell, 1, "-");
      printf("  %-*s", (int)wcol[i], cell);
    }
    printf("\n");
  }
done:
  for (i = 0; i < nruns; ++i)
    if (runs[i].doc) fy_document_destroy(runs[i].doc);
  return code;
}
