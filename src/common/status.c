#include "fesd_status.h"

const char *fesd_status_string(int status) {
  switch (status) {
#define FESD_X_CASE(name, value, msg) \
  case name:                          \
    return msg;
    FESD_STATUS_LIST(FESD_X_CASE)
#undef FESD_X_CASE
  default:
    return "unknown status";
  }
}

const char *fesd_status_name(int status) {
  switch (status) {
#define FESD_X_CASE(name, value, msg) \
  case name:                          \
    return #name;
    FESD_STATUS_LIST(FESD_X_CASE)
#undef FESD_X_CASE
  default:
    return "FESD_UNKNOWN";
  }
}
