/* Colormaps for pictures: perceptually uniform sequential maps (viridis,
 * inferno) and a diverging map (coolwarm) for signed fields such as vortex
 * circulation, evaluated by linear interpolation between published control
 * points (sources in src/io/colormap.c). */
#ifndef PARTIX_COLORMAP_H
#define PARTIX_COLORMAP_H

#include "partix/context.h"
#include "partix/export.h"

#ifdef __cplusplus
extern "C" {
#endif

enum px_colormap {
  PX_COLORMAP_VIRIDIS = 0, /* sequential, dark blue -> yellow */
  PX_COLORMAP_INFERNO = 1, /* sequential, black -> pale yellow */
  PX_COLORMAP_COOLWARM = 2 /* diverging, blue -> grey -> red (Moreland 2009) */
};

/* sRGB colour (components in [0, 1]) at t in [0, 1] (clamped); a NaN t gives
 * the "no data" grey of px_colormap_nan. */
PX_API void px_colormap_eval(enum px_colormap map, double t, double rgb[3]);
/* The grey used for NaN values. */
PX_API void px_colormap_nan(double rgb[3]);
/* 1 for diverging maps (their automatic range is symmetric around 0). */
PX_API int px_colormap_is_diverging(enum px_colormap map);
PX_API const char *px_colormap_name(enum px_colormap map);
/* "viridis" | "inferno" | "coolwarm"; PX_STATUS_INVALID (with the list of
 * names in the message) otherwise. */
PX_API enum px_status px_colormap_parse(struct px_context *ctx, const char *name,
                                        enum px_colormap *out);

#ifdef __cplusplus
}
#endif
#endif
