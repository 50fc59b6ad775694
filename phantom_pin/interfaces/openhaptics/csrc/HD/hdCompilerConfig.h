/* phantom_pin's stand-in for OpenHaptics' libHD: the calling conventions of the HDAPI.
 * On Linux OpenHaptics' functions and callbacks use the C calling convention, so the macros
 * that its headers put in every declaration (HDAPI, HDAPIENTRY, HDCALLBACK) are empty here.
 * Names as in OpenHaptics 3.x's HD/hdCompilerConfig.h and HD/hdExport.h (docs/servo-loop.md). */
#ifndef HD_COMPILER_CONFIG_H_DEFINE
#define HD_COMPILER_CONFIG_H_DEFINE

#ifndef HDCALLBACK
#define HDCALLBACK
#endif

#endif /* HD_COMPILER_CONFIG_H_DEFINE */
