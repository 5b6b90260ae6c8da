/* Tests that draw text: release cairo's and fontconfig's process-wide caches
 * (font faces, the parsed font configuration) before exit, so that
 * LeakSanitizer reports only real leaks. The caches are bounded: they do not
 * grow with the number of pictures drawn. */
#ifndef PX_TEST_FONTS_H
#define PX_TEST_FONTS_H

#include <cairo.h>
#include <fontconfig/fontconfig.h>

static void px_test_release_fonts(void) {
  cairo_debug_reset_static_data();
  FcFini();
}

#endif
