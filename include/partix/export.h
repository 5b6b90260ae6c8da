/* Symbol visibility for the partix library. Every exported symbol carries the
 * px_ prefix (checked by tests/core/test_symbols). */
#ifndef PARTIX_EXPORT_H
#define PARTIX_EXPORT_H

#if defined(__GNUC__) || defined(__clang__)
#define PX_API __attribute__((visibility("default")))
#define PX_PRINTF(fmt_index, first_arg) __attribute__((format(printf, fmt_index, first_arg)))
#else
#define PX_API
#define PX_PRINTF(fmt_index, first_arg)
#endif

#endif
