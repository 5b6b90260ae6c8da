/* The platform's own top-level keys (solver, title, backend, time, output)
 * and the root schema that joins them with the solver sections. */
#include <string.h>

#include "config/case_impl.h"
#include "config/schema.h"

static const char *const px_platform_backend_types[] = {"cpu", "opencl", NULL};
static const char *const px_platform_precisions[] = {"single", "double", "mixed", NULL};

static const struct px_schema px_platform_backend_keys[] = {
    PX_KEY_ENUM("type", px_platform_backend_types, "compute backend", PX_DEFAULT("cpu")),
    PX_KEY_INT("device",
               "OpenCL device index, as listed by `partix info` (not given: the first GPU or "
               "accelerator listed, else device 0)",
               PX_IN(0, 1024)),
    PX_KEY_INT("node_devices",
               "OpenCL devices the MPI ranks of one node share out: the node's i-th rank uses "
               "device + (i mod node_devices), e.g. 4 on a node with 4 GPUs and 4 ranks",
               PX_IN(1, 1024), PX_DEFAULT("1")),
    PX_KEY_INT("threads", "CPU threads (0 = all cores)", PX_IN(0, 1024), PX_DEFAULT("0")),
    PX_KEY_ENUM("precision", px_platform_precisions,
                "floating-point precision (mixed: as the solver's spec says)", PX_DEFAULT("mixed")),
    PX_KEY_INT("workgroup", "OpenCL work-group size (0 = automatic)", PX_IN(0, 1048576),
               PX_DEFAULT("0")),
    PX_KEY_END};

/* Drop member `key` of map `m` (the resolved tree then reads as if it had
 * never been written). */
static void px_platform_drop(struct px_case_node *m, const char *key) {
  size_t i, j;
  for (i = j = 0; i < m->n; ++i)
    if (!(m->items[i]->key_len == strlen(key) &&
          memcmp(m->items[i]->key, key, m->items[i]->key_len) == 0))
      m->items[j++] = m->items[i];
  m->n = j;
}

/* Exactly one of steps / end. A --set override of one (e.g. `--steps 10`
 * on a case written with `end`) replaces the other written in the file. */
static enum px_status px_platform_check_time(struct px_case *c, const char *path) {
  char steps_path[256], end_path[256];
  int steps = px_case_has(c, px_case_path_join(steps_path, sizeof steps_path, path, "steps"));
  int end = px_case_has(c, px_case_path_join(end_path, sizeof end_path, path, "end"));
  if (steps && end && c->root && strchr(path, '.') == NULL) {
    struct px_case_node *t = px_case_node_member(c->root, path, strlen(path));
    struct px_case_node *ns = t ? px_case_node_member(t, "steps", 5) : NULL;
    struct px_case_node *ne = t ? px_case_node_member(t, "end", 3) : NULL;
    int ov_s = ns && ns->loc.origin >= 0, ov_e = ne && ne->loc.origin >= 0;
    if (ov_s != ov_e) {
      px_platform_drop(t, ov_s ? "end" : "steps");
      return PX_STATUS_OK;
    }
  }
  if (steps && end) return px_case_fail(c, path, "give either 'steps' or 'end', not both");
  if (!steps && !end)
    return px_case_fail(c, path,
                        "missing 'steps' or 'end' (give exactly one: the number of time steps, "
                        "or the end time [s])");
  return PX_STATUS_OK;
}

static const struct px_schema px_platform_time_keys[] = {
    PX_KEY_REAL("dt", "time step [s] (solvers that choose it themselves may leave it out)",
                PX_GT(0)),
    PX_KEY_INT("steps", "number of time steps (give steps or end)", PX_IN(1, 1e12)),
    PX_KEY_REAL("end", "end time [s] (give steps or end)", PX_GT(0)), PX_KEY_END};

static const struct px_schema px_platform_output_keys[] = {
    PX_KEY_STRING("dir", "output directory (created if missing)", PX_DEFAULT("out")),
    PX_KEY_INT("every", "snapshot period [steps]", PX_GE(1), PX_DEFAULT("100")),
    PX_KEY_BOOL("vtk", "write VTK files for ParaView", PX_DEFAULT("true")),
    PX_KEY_BOOL("csv", "write CSV time series", PX_DEFAULT("true")),
    PX_KEY_BOOL("png", "write PNG pictures", PX_DEFAULT("true")),
    PX_KEY_INT("png_every", "picture period [steps] (0 = same as every)", PX_GE(0),
               PX_DEFAULT("0")),
    PX_KEY_INT("checkpoint_every", "checkpoint period [steps] (0 = only at the end and on Ctrl-C)",
               PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_INT("log_every", "CSV time-series period [steps]", PX_GE(1), PX_DEFAULT("1")),
    PX_KEY_END};

/* The platform keys; `solver` gets its choices when the root is built. */
static const struct px_schema px_platform_keys[] = {
    PX_KEY_ENUM(PX_CASE_SOLVER_KEY, NULL, "solver to run", PX_REQUIRED, PX_WHAT("solver")),
    PX_KEY_STRING("title", "title of the run (shown in pictures and logs)"),
    PX_KEY_MAP("backend", px_platform_backend_keys, "where and how the computation runs"),
    PX_KEY_MAP("time", px_platform_time_keys, "time stepping", PX_VALIDATE(px_platform_check_time)),
    PX_KEY_MAP("output", px_platform_output_keys, "what is written, where and how often"),
    PX_KEY_END};

const struct px_schema *px_case_root_schema_build(const struct px_schema *sections,
                                                  struct px_case_root_storage *st) {
  size_t n = 0, i, j, k = 0;
  while (sections && sections[n].name) ++n;
  if (n > PX_CASE_MAX_SECTIONS) return NULL;
  memset(st, 0, sizeof *st);
  for (i = 0; i < n; ++i) {
    for (j = 0; px_platform_keys[j].name; ++j)
      if (strcmp(px_platform_keys[j].name, sections[i].name) == 0) return NULL;
    st->choices[i] = sections[i].name;
  }
  st->choices[n] = NULL;
  for (j = 0; px_platform_keys[j].name; ++j) {
    st->keys[k] = px_platform_keys[j];
    if (strcmp(st->keys[k].name, PX_CASE_SOLVER_KEY) == 0) st->keys[k].choices = st->choices;
    ++k;
  }
  for (i = 0; i < n; ++i) {
    st->keys[k] = sections[i];
    st->keys[k].section = 1;
    ++k;
  }
  st->keys[k].name = NULL;
  st->root.name = "";
  st->root.type = PX_SCHEMA_TYPE_MAP;
  st->root.doc = "a partix case";
  st->root.keys = st->keys;
  return &st->root;
}
