/* phantom_pin's stand-in for OpenHaptics' libHD: the export macros of the HDAPI's
 * declarations (empty: plain C linkage from a shared library on Linux). */
#ifndef HD_EXPORT_H_DEFINE
#define HD_EXPORT_H_DEFINE

#ifndef HDAPI
#define HDAPI __attribute__((visibility("default")))
#endif
#ifndef HDAPIENTRY
#define HDAPIENTRY
#endif

#endif /* HD_EXPORT_H_DEFINE */
