#include "partix/status.h"

static const char *const px_status_messages[] = {
#define PX_STATUS_MSG_(name, msg) msg,
    PX_STATUS_LIST(PX_STATUS_MSG_)
#undef PX_STATUS_MSG_
};

static const char *const px_status_names[] = {
#define PX_STATUS_NAME_(name, msg) #name,
    PX_STATUS_LIST(PX_STATUS_NAME_)
#undef PX_STATUS_NAME_
};

const char *px_status_message(enum px_status status) {
  if ((unsigned)status >= (unsigned)PX_STATUS_COUNT_) return "unknown status";
  return px_status_messages[status];
}

const char *px_status_name(enum px_status status) {
  if ((unsigned)status >= (unsigned)PX_STATUS_COUNT_) return "UNKNOWN";
  return px_status_names[status];
}
