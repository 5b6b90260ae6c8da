/* partix._core: the CPython extension under the `partix` package (the
 * Python API is partix/__init__.py). A Sim owns a context and a run; its
 * results come out as NumPy arrays over px_results memory (partix/results.h)
 * without a further copy, read-only, each keeping its results object alive.
 * Steps run with the GIL released; Ctrl-C during them stops after the step
 * in progress and raises KeyboardInterrupt. Errors raise partix.Error (the
 * status name and the library's message); nothing aborts the interpreter. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <signal.h>
#include <string.h>

#include "partix/partix.h"

static PyObject *px_py_error; /* partix._core.Error(status, message) */

/* ---- errors ------------------------------------------------------------- */

/* Raise Error(status name, message) from the context's last failure. */
static PyObject *px_py_raise(struct px_context *ctx, enum px_status s) {
  const char *msg = ctx ? px_context_message(ctx) : "";
  PyObject *args = Py_BuildValue("(ss)", px_status_name(s), msg[0] ? msg : px_status_message(s));
  if (args) {
    PyErr_SetObject(px_py_error, args);
    Py_DECREF(args);
  }
  return NULL;
}

/* A Python list of str -> a C array of borrowed UTF-8 pointers (the list
 * must outlive it). */
static const char **px_py_strings(PyObject *list, Py_ssize_t *n) {
  const char **out;
  Py_ssize_t i;
  *n = 0;
  if (!list || list == Py_None) return PyMem_Calloc(1, sizeof *out);
  if (!PyList_Check(list)) {
    PyErr_SetString(PyExc_TypeError, "overrides must be a list of 'key=value' strings");
    return NULL;
  }
  *n = PyList_Size(list);
  out = PyMem_Calloc((size_t)*n + 1, sizeof *out);
  if (!out) return (const char **)PyErr_NoMemory();
  for (i = 0; i < *n; ++i) {
    out[i] = PyUnicode_AsUTF8(PyList_GetItem(list, i));
    if (!out[i]) {
      PyMem_Free(out);
      return NULL;
    }
  }
  return out;
}

/* ---- results: the owner of the arrays' memory -------------------------- */

typedef struct {
  PyObject_HEAD struct px_results *r;
} px_py_results;

static void px_py_results_dealloc(px_py_results *self) {
  px_results_free(self->r);
  Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyTypeObject px_py_results_type = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "partix._core.Results",
    .tp_basicsize = sizeof(px_py_results),
    .tp_dealloc = (destructor)px_py_results_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "memory of a set of result arrays (freed with the last array)",
};

static int px_py_npy_type(enum px_view_type t) {
  switch (t) {
    case PX_VIEW_F64: return NPY_FLOAT64;
    case PX_VIEW_F32: return NPY_FLOAT32;
    case PX_VIEW_I64: return NPY_INT64;
    case PX_VIEW_I32: return NPY_INT32;
    case PX_VIEW_U8: return NPY_UINT8;
  }
  return NPY_FLOAT64;
}

/* ({name: array}, {name: units}, step, time) over r (ownership of r passes
 * to the arrays). */
static PyObject *px_py_results_dict(struct px_results *r) {
  px_py_results *owner = PyObject_New(px_py_results, &px_py_results_type);
  PyObject *arrays = NULL, *units = NULL, *out = NULL;
  size_t i;
  if (!owner) {
    px_results_free(r);
    return NULL;
  }
  owner->r = r;
  arrays = PyDict_New();
  units = PyDict_New();
  for (i = 0; arrays && units && i < px_results_count(r); ++i) {
    const struct px_view *v = px_results_view(r, i);
    npy_intp dims[2] = {(npy_intp)v->length, (npy_intp)v->components};
    npy_intp strides[2] = {(npy_intp)v->stride, (npy_intp)px_view_type_size(v->type)};
    PyObject *a = PyArray_New(&PyArray_Type, v->components > 1 ? 2 : 1, dims,
                              px_py_npy_type(v->type), strides, (void *)v->data, 0, 0, NULL);
    PyObject *u = PyUnicode_FromString(v->units);
    int bad = !a || !u;
    if (!bad) {
      PyArray_CLEARFLAGS((PyArrayObject *)a, NPY_ARRAY_WRITEABLE);
      Py_INCREF(owner); /* PyArray_SetBaseObject steals it */
      bad = PyArray_SetBaseObject((PyArrayObject *)a, (PyObject *)owner) != 0;
    }
    if (!bad) bad = PyDict_SetItemString(arrays, v->name, a) != 0;
    if (!bad) bad = PyDict_SetItemString(units, v->name, u) != 0;
    Py_XDECREF(a);
    Py_XDECREF(u);
    if (bad) Py_CLEAR(arrays);
  }
  if (arrays && units)
    out = Py_BuildValue("(OOld)", arrays, units, px_results_step(r), px_results_time(r));
  Py_XDECREF(arrays);
  Py_XDECREF(units);
  Py_DECREF(owner);
  return out;
}

/* ---- Ctrl-C while the GIL is released ----------------------------------- */

static volatile sig_atomic_t px_py_interrupt = 0;
static void px_py_on_sigint(int sig) {
  (void)sig;
  px_py_interrupt = 1;
}

/* Steps run under our SIGINT handler: Python's own sets a flag only the
 * interpreter reads, which it cannot while a step holds no GIL. Only from
 * the main thread (`own`), where Python delivers signals. */
struct px_py_sigint {
  struct sigaction old;
  int installed;
};

static void px_py_sigint_begin(struct px_context *ctx, int own, struct px_py_sigint *g) {
  struct sigaction sa;
  g->installed = 0;
  px_py_interrupt = 0;
  px_context_set_interrupt_flag(ctx, &px_py_interrupt);
  if (!own) return;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = px_py_on_sigint;
  sigemptyset(&sa.sa_mask);
  g->installed = sigaction(SIGINT, &sa, &g->old) == 0;
}

/* Restore Python's handler; 1 when Ctrl-C came. */
static int px_py_sigint_end(struct px_context *ctx, struct px_py_sigint *g) {
  int hit = px_py_interrupt != 0;
  if (g->installed) sigaction(SIGINT, &g->old, NULL);
  px_context_set_interrupt_flag(ctx, NULL);
  px_py_interrupt = 0;
  return hit;
}

/* ---- Sim ---------------------------------------------------------------- */

typedef struct {
  PyObject_HEAD struct px_context *ctx;
  struct px_sim *sim;
} px_py_sim;

static void px_py_sim_dealloc(px_py_sim *self) {
  px_sim_free(self->sim);
  px_context_free(self->ctx);
  Py_TYPE(self)->tp_free((PyObject *)self);
}

/* A context logging warnings and errors (to stderr) unless `level` says
 * otherwise ("error", "warning", "info", "debug"). */
static struct px_context *px_py_context(const char *level) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return (struct px_context *)PyErr_NoMemory();
  px_context_set_log_level(ctx, !level || strcmp(level, "warning") == 0 ? PX_LOG_LEVEL_WARN
                                : strcmp(level, "error") == 0           ? PX_LOG_LEVEL_ERROR
                                : strcmp(level, "info") == 0            ? PX_LOG_LEVEL_INFO
                                                                        : PX_LOG_LEVEL_DEBUG);
  return ctx;
}

static PyTypeObject px_py_sim_type;

/* Sim(path, overrides, mode, log, resume): mode 0 run, 1 check; resume: path
 * is a checkpoint. */
static int px_py_sim_init(px_py_sim *self, PyObject *args, PyObject *kw) {
  static char *names[] = {"path", "overrides", "mode", "log", "resume", NULL};
  const char *path, *level = "warning", **ov;
  PyObject *list = NULL;
  int mode = 0, resume = 0;
  Py_ssize_t n;
  struct px_case *c = NULL;
  enum px_status s;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "s|Oisp", names, &path, &list, &mode, &level, &resume))
    return -1;
  if (self->sim) {
    PyErr_SetString(PyExc_RuntimeError, "Sim already initialised");
    return -1;
  }
  if (strcmp(level, "error") != 0 && strcmp(level, "warning") != 0 && strcmp(level, "info") != 0 &&
      strcmp(level, "debug") != 0) {
    PyErr_Format(PyExc_ValueError, "log: one of 'error', 'warning', 'info', 'debug', not '%s'",
                 level);
    return -1;
  }
  ov = px_py_strings(list, &n);
  if (!ov) return -1;
  self->ctx = px_py_context(level);
  if (!self->ctx) {
    PyMem_Free(ov);
    return -1;
  }
  Py_BEGIN_ALLOW_THREADS;
  if (resume) {
    s = px_sim_resume(self->ctx, path, ov, (size_t)n, &self->sim);
  } else {
    s = px_case_load(self->ctx, path, ov, (size_t)n, &c);
    if (s == PX_STATUS_OK)
      s = px_sim_create(self->ctx, c, mode ? PX_SIM_MODE_CHECK : PX_SIM_MODE_RUN, &self->sim);
  }
  Py_END_ALLOW_THREADS;
  PyMem_Free(ov);
  if (s != PX_STATUS_OK) {
    px_py_raise(self->ctx, s);
    return -1;
  }
  px_sim_set_progress(self->sim, NULL, 0);
  return 0;
}

static int px_py_sim_ready(px_py_sim *self) {
  if (self->sim) return 1;
  PyErr_SetString(PyExc_RuntimeError, "the simulation is closed");
  return 0;
}

/* step(n, own_sigint): n steps (fewer at the run's end); returns the steps
 * done. */
static PyObject *px_py_sim_step(px_py_sim *self, PyObject *args) {
  long n = 1, done = 0;
  int own = 1, hit, ended = 0;
  struct px_py_sigint g;
  enum px_status s = PX_STATUS_OK;
  if (!PyArg_ParseTuple(args, "|lp", &n, &own) || !px_py_sim_ready(self)) return NULL;
  if (n < 0) {
    PyErr_Format(PyExc_ValueError, "step(n): n is 0 or more steps, not %ld", n);
    return NULL;
  }
  px_py_sigint_begin(self->ctx, own, &g);
  Py_BEGIN_ALLOW_THREADS;
  for (; done < n && !px_py_interrupt; ++done) {
    if (px_sim_ended(self->sim)) {
      ended = 1;
      break;
    }
    s = px_sim_step(self->sim);
    if (s != PX_STATUS_OK) break;
  }
  Py_END_ALLOW_THREADS;
  hit = px_py_sigint_end(self->ctx, &g);
  if (s != PX_STATUS_OK) return px_py_raise(self->ctx, s);
  if (hit) {
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    return NULL;
  }
  (void)ended; /* fewer steps than asked: the caller sees `done` */
  return PyLong_FromLong(done);
}

/* run(own_sigint, progress): to the end (Ctrl-C: a checkpoint, then
 * KeyboardInterrupt). */
static PyObject *px_py_sim_run(px_py_sim *self, PyObject *args) {
  int own = 1, progress = 0, hit;
  struct px_py_sigint g;
  enum px_status s;
  if (!PyArg_ParseTuple(args, "|pp", &own, &progress) || !px_py_sim_ready(self)) return NULL;
  px_sim_set_progress(self->sim, progress ? stderr : NULL, -1);
  px_py_sigint_begin(self->ctx, own, &g);
  Py_BEGIN_ALLOW_THREADS;
  s = px_sim_run(self->sim);
  Py_END_ALLOW_THREADS;
  hit = px_py_sigint_end(self->ctx, &g);
  px_sim_set_progress(self->sim, NULL, 0);
  if (s == PX_STATUS_INTERRUPTED || (hit && s == PX_STATUS_OK)) {
    PyErr_SetString(PyExc_KeyboardInterrupt, px_context_message(self->ctx));
    return NULL;
  }
  if (s != PX_STATUS_OK) return px_py_raise(self->ctx, s);
  Py_RETURN_NONE;
}

static PyObject *px_py_sim_results(px_py_sim *self, PyObject *args) {
  int kind = 0;
  struct px_results *r = NULL;
  enum px_status s;
  if (!PyArg_ParseTuple(args, "|i", &kind) || !px_py_sim_ready(self)) return NULL;
  Py_BEGIN_ALLOW_THREADS;
  s = px_sim_results(self->sim, (enum px_results_kind)kind, &r);
  Py_END_ALLOW_THREADS;
  if (s != PX_STATUS_OK) return px_py_raise(self->ctx, s);
  return px_py_results_dict(r);
}

static PyObject *px_py_sim_series(px_py_sim *self, PyObject *args) {
  const char *name;
  struct px_results *r = NULL;
  enum px_status s;
  if (!PyArg_ParseTuple(args, "s", &name) || !px_py_sim_ready(self)) return NULL;
  s = px_sim_series(self->sim, name, &r);
  if (s != PX_STATUS_OK) return px_py_raise(self->ctx, s);
  return px_py_results_dict(r);
}

static PyObject *px_py_sim_series_names(px_py_sim *self, PyObject *unused) {
  PyObject *list;
  const char *name;
  size_t i;
  (void)unused;
  if (!px_py_sim_ready(self)) return NULL;
  list = PyList_New(0);
  for (i = 0; list && (name = px_sim_series_name(self->sim, i)) != NULL; ++i) {
    PyObject *o = PyUnicode_FromString(name);
    if (!o || PyList_Append(list, o) != 0) Py_CLEAR(list);
    Py_XDECREF(o);
  }
  return list;
}

static PyObject *px_py_sim_checkpoint(px_py_sim *self, PyObject *unused) {
  enum px_status s;
  (void)unused;
  if (!px_py_sim_ready(self)) return NULL;
  Py_BEGIN_ALLOW_THREADS;
  s = px_sim_checkpoint(self->sim);
  Py_END_ALLOW_THREADS;
  if (s != PX_STATUS_OK) return px_py_raise(self->ctx, s);
  return PyUnicode_FromString(px_sim_checkpoint_path(self->sim));
}

static PyObject *px_py_sim_close(px_py_sim *self, PyObject *unused) {
  (void)unused;
  px_sim_free(self->sim);
  self->sim = NULL;
  Py_RETURN_NONE;
}

/* info() -> (step, steps, time, dt, output dir, checkpoint path, solver). */
static PyObject *px_py_sim_info(px_py_sim *self, PyObject *unused) {
  (void)unused;
  if (!px_py_sim_ready(self)) return NULL;
  return Py_BuildValue("(llddsss)", px_sim_step_index(self->sim), px_sim_step_count(self->sim),
                       px_sim_time(self->sim), px_sim_dt(self->sim), px_sim_output_dir(self->sim),
                       px_sim_checkpoint_path(self->sim), px_case_solver(px_sim_case(self->sim)));
}

static PyMethodDef px_py_sim_methods[] = {
    {"step", (PyCFunction)px_py_sim_step, METH_VARARGS, "step(n=1, own_sigint=True) -> steps done"},
    {"run", (PyCFunction)px_py_sim_run, METH_VARARGS, "run(own_sigint=True, progress=False)"},
    {"results", (PyCFunction)px_py_sim_results, METH_VARARGS,
     "results(kind=0) -> (arrays, units, step, time); kind 0 state, 1 segments"},
    {"series", (PyCFunction)px_py_sim_series, METH_VARARGS,
     "series(name) -> (arrays, units, step, time)"},
    {"series_names", (PyCFunction)px_py_sim_series_names, METH_NOARGS, "names of the series"},
    {"checkpoint", (PyCFunction)px_py_sim_checkpoint, METH_NOARGS, "write a checkpoint -> path"},
    {"close", (PyCFunction)px_py_sim_close, METH_NOARGS, "free the run"},
    {"info", (PyCFunction)px_py_sim_info, METH_NOARGS,
     "(step, steps, time, dt, output dir, checkpoint path, solver)"},
    {NULL, NULL, 0, NULL}};

static PyTypeObject px_py_sim_type = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "partix._core.Sim",
    .tp_basicsize = sizeof(px_py_sim),
    .tp_dealloc = (destructor)px_py_sim_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE,
    .tp_doc = "Sim(path, overrides=None, mode=0, log='warning', resume=False)",
    .tp_methods = px_py_sim_methods,
    .tp_init = (initproc)px_py_sim_init,
    .tp_new = PyType_GenericNew,
};

/* ---- module ------------------------------------------------------------- */

static PyObject *px_py_version(PyObject *self, PyObject *unused) {
  (void)self;
  (void)unused;
  return PyUnicode_FromString(px_version());
}

static PyObject *px_py_solvers(PyObject *self, PyObject *unused) {
  const char *const *names = px_sim_solver_names();
  PyObject *list = PyList_New(0);
  (void)self;
  (void)unused;
  for (; list && *names; ++names) {
    PyObject *o = PyUnicode_FromString(*names);
    if (!o || PyList_Append(list, o) != 0) Py_CLEAR(list);
    Py_XDECREF(o);
  }
  return list;
}

static PyMethodDef px_py_methods[] = {
    {"version", px_py_version, METH_NOARGS, "the library's version"},
    {"solvers", px_py_solvers, METH_NOARGS, "the solvers built in"},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef px_py_module = {
    PyModuleDef_HEAD_INIT,
    .m_name = "partix._core",
    .m_doc = "partix's C library (use the partix package)",
    .m_size = -1,
    .m_methods = px_py_methods,
};

PyMODINIT_FUNC PyInit__core(void);
PyMODINIT_FUNC PyInit__core(void) {
  PyObject *m;
  import_array();
  if (PyType_Ready(&px_py_sim_type) < 0 || PyType_Ready(&px_py_results_type) < 0) return NULL;
  m = PyModule_Create(&px_py_module);
  if (!m) return NULL;
  px_py_error = PyErr_NewExceptionWithDoc("partix._core.Error",
                                          "a partix failure: args (status, message)", NULL, NULL);
  Py_INCREF(&px_py_sim_type);
  if (!px_py_error || PyModule_AddObject(m, "Error", px_py_error) < 0 ||
      PyModule_AddObject(m, "Sim", (PyObject *)&px_py_sim_type) < 0) {
    Py_DECREF(m);
    return NULL;
  }
  Py_INCREF(px_py_error);
  return m;
}
