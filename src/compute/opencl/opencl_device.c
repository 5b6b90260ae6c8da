/* The opencl backend: OpenCL platforms and devices, numbered over all
 * platforms in platform order, their capabilities, and `partix info`. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compute/opencl/opencl_impl.h"

/* ------------------------------------------------------------------------ */
/* Device enumeration (all platforms, in platform order)                     */

/* Platforms into *out (malloc'ed, tiny table); 0 when there is no ICD. */
cl_uint px_opencl_platforms(cl_platform_id **out) {
  cl_uint n = 0;
  *out = NULL;
  if (clGetPlatformIDs(0, NULL, &n) != CL_SUCCESS || n == 0) return 0;
  *out = malloc(n * sizeof **out);
  if (!*out) return 0;
  if (clGetPlatformIDs(n, *out, NULL) != CL_SUCCESS) {
    free(*out);
    *out = NULL;
    return 0;
  }
  return n;
}

cl_uint px_opencl_platform_devices(cl_platform_id p, cl_device_id **out) {
  cl_uint n = 0;
  *out = NULL;
  if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 0, NULL, &n) != CL_SUCCESS || n == 0) return 0;
  *out = malloc(n * sizeof **out);
  if (!*out) return 0;
  if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, n, *out, NULL) != CL_SUCCESS) {
    free(*out);
    *out = NULL;
    return 0;
  }
  return n;
}

cl_uint px_opencl_devices(cl_device_id **devs, cl_platform_id **plats, cl_uint *nplat) {
  cl_platform_id *ps;
  cl_uint np = px_opencl_platforms(&ps), i, j, n = 0;
  *devs = NULL;
  *plats = NULL;
  if (nplat) *nplat = np;
  for (i = 0; i < np; ++i) {
    cl_device_id *ds, *d2;
    cl_platform_id *p2;
    cl_uint nd = px_opencl_platform_devices(ps[i], &ds);
    if (nd == 0) continue;
    d2 = realloc(*devs, (n + nd) * sizeof **devs);
    if (d2) *devs = d2;
    p2 = realloc(*plats, (n + nd) * sizeof **plats);
    if (p2) *plats = p2;
    if (!d2 || !p2) { /* out of memory: the devices listed so far */
      free(ds);
      break;
    }
    for (j = 0; j < nd; ++j, ++n) {
      (*devs)[n] = ds[j];
      (*plats)[n] = ps[i];
    }
    free(ds);
  }
  free(ps);
  if (n == 0) {
    free(*devs);
    free(*plats);
    *devs = NULL;
    *plats = NULL;
  }
  return n;
}

int px_opencl_device_count(struct px_context *ctx) {
  cl_device_id *ds;
  cl_platform_id *ps;
  const cl_uint n = px_opencl_devices(&ds, &ps, NULL);
  (void)ctx;
  free(ds);
  free(ps);
  return (int)n;
}

void px_opencl_string(cl_device_id d, cl_device_info what, char *buf, size_t size) {
  buf[0] = '\0';
  if (clGetDeviceInfo(d, what, size, buf, NULL) != CL_SUCCESS) snprintf(buf, size, "?");
  buf[size - 1] = '\0';
}

/* 1 if the space-separated list `list` contains `token`. */
static int px_opencl_has_token(const char *list, const char *token) {
  size_t len = strlen(token);
  const char *p = list;
  while ((p = strstr(p, token)) != NULL) {
    if ((p == list || p[-1] == ' ') && (p[len] == ' ' || p[len] == '\0')) return 1;
    p += len;
  }
  return 0;
}

/* fp64 is usable when the device advertises cl_khr_fp64 (or, on OpenCL 3.0,
 * the __opencl_c_fp64 feature shows up as a non-zero double FP config) and
 * reports a non-empty CL_DEVICE_DOUBLE_FP_CONFIG. */
int px_opencl_query_fp64(cl_device_id d) {
  char ext[4096];
  cl_device_fp_config cfg = 0;
  size_t len = 0;
  if (clGetDeviceInfo(d, CL_DEVICE_EXTENSIONS, 0, NULL, &len) != CL_SUCCESS) return 0;
  if (len > sizeof ext) {
    char *big = malloc(len);
    int has;
    if (!big) return 0;
    has = clGetDeviceInfo(d, CL_DEVICE_EXTENSIONS, len, big, NULL) == CL_SUCCESS &&
          px_opencl_has_token(big, "cl_khr_fp64");
    free(big);
    if (!has) return 0;
  } else {
    px_opencl_string(d, CL_DEVICE_EXTENSIONS, ext, sizeof ext);
    if (!px_opencl_has_token(ext, "cl_khr_fp64")) return 0;
  }
  if (clGetDeviceInfo(d, CL_DEVICE_DOUBLE_FP_CONFIG, sizeof cfg, &cfg, NULL) != CL_SUCCESS)
    return 0;
  return cfg != 0;
}

static const char *px_opencl_type_name(cl_device_type t) {
  if (t & CL_DEVICE_TYPE_GPU) return "GPU";
  if (t & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  if (t & CL_DEVICE_TYPE_CPU) return "CPU";
  return "other";
}

/* "OpenCL C 1.2 PoCL" -> 1, 2 */
void px_opencl_c_version(const char *s, int *major, int *minor) {
  *major = 0;
  *minor = 0;
  if (strncmp(s, "OpenCL C ", 9) == 0) sscanf(s + 9, "%d.%d", major, minor);
}

int px_opencl_pick_default(const cl_device_type *types, int n) {
  int k;
  for (k = 0; k < n; ++k)
    if (types[k] & (CL_DEVICE_TYPE_GPU | CL_DEVICE_TYPE_ACCELERATOR)) return k;
  return 0;
}

int px_opencl_default_device(void) {
  cl_device_id *ds;
  cl_platform_id *ps;
  cl_device_type types[256];
  const cl_uint nd = px_opencl_devices(&ds, &ps, NULL);
  int n;
  for (n = 0; n < (int)nd && n < (int)PX_COUNTOF(types); ++n) {
    types[n] = 0;
    clGetDeviceInfo(ds[n], CL_DEVICE_TYPE, sizeof types[n], &types[n], NULL);
  }
  free(ds);
  free(ps);
  return px_opencl_pick_default(types, n);
}

void px_opencl_report(struct px_context *ctx, FILE *out) {
  cl_platform_id *ps;
  cl_uint np = px_opencl_platforms(&ps), i, j;
  int index = 0;
  const int def = px_opencl_default_device();
  (void)ctx;
  if (np == 0) {
    fprintf(out, "  opencl: no OpenCL platform found (no ICD installed or none loadable)\n");
    return;
  }
  for (i = 0; i < np; ++i) {
    char name[256], vendor[256], version[256];
    cl_device_id *ds;
    cl_uint nd;
    if (clGetPlatformInfo(ps[i], CL_PLATFORM_NAME, sizeof name, name, NULL) != CL_SUCCESS)
      snprintf(name, sizeof name, "?");
    if (clGetPlatformInfo(ps[i], CL_PLATFORM_VENDOR, sizeof vendor, vendor, NULL) != CL_SUCCESS)
      snprintf(vendor, sizeof vendor, "?");
    if (clGetPlatformInfo(ps[i], CL_PLATFORM_VERSION, sizeof version, version, NULL) != CL_SUCCESS)
      snprintf(version, sizeof version, "?");
    name[sizeof name - 1] = vendor[sizeof vendor - 1] = version[sizeof version - 1] = '\0';
    fprintf(out, "  opencl platform %u: %s (%s), %s\n", i, name, vendor, version);
    nd = px_opencl_platform_devices(ps[i], &ds);
    if (nd == 0) fprintf(out, "    no devices\n");
    for (j = 0; j < nd; ++j, ++index) {
      char dname[256], cver[128];
      cl_device_type type = 0;
      cl_uint cu = 0, clock = 0;
      cl_ulong gmem = 0, lmem = 0;
      size_t wg = 0;
      px_opencl_string(ds[j], CL_DEVICE_NAME, dname, sizeof dname);
      px_opencl_string(ds[j], CL_DEVICE_OPENCL_C_VERSION, cver, sizeof cver);
      clGetDeviceInfo(ds[j], CL_DEVICE_TYPE, sizeof type, &type, NULL);
      clGetDeviceInfo(ds[j], CL_DEVICE_MAX_COMPUTE_UNITS, sizeof cu, &cu, NULL);
      clGetDeviceInfo(ds[j], CL_DEVICE_MAX_CLOCK_FREQUENCY, sizeof clock, &clock, NULL);
      clGetDeviceInfo(ds[j], CL_DEVICE_GLOBAL_MEM_SIZE, sizeof gmem, &gmem, NULL);
      clGetDeviceInfo(ds[j], CL_DEVICE_LOCAL_MEM_SIZE, sizeof lmem, &lmem, NULL);
      clGetDeviceInfo(ds[j], CL_DEVICE_MAX_WORK_GROUP_SIZE, sizeof wg, &wg, NULL);
      fprintf(out,
              "    device %d: %s%s\n"
              "      type %s, %u compute units at %u MHz, global memory %.1f MiB, "
              "local memory %.1f KiB\n"
              "      max work-group size %zu, fp64 %s, %s\n",
              index, dname, index == def ? " (the default: backend.device not given)" : "",
              px_opencl_type_name(type), cu, clock, (double)gmem / (1024.0 * 1024.0),
              (double)lmem / 1024.0, wg, px_opencl_query_fp64(ds[j]) ? "yes" : "no", cver);
    }
    free(ds);
  }
  free(ps);
}
