/* phantom_pin's stand-in for OpenHaptics' libHD: the device functions of the HDAPI, with
 * OpenHaptics 3.x's signatures (its HD/hdDevice.h, as the public sources of docs/servo-loop.md
 * give them; pyOpenHaptics 1.0.1's hd.py calls the same). */
#ifndef HD_DEVICE_H_DEFINE
#define HD_DEVICE_H_DEFINE

#include <HD/hdExport.h>
#include <HD/hdCompilerConfig.h>
#include <HD/hdDefines.h>

#ifdef __cplusplus
extern "C" {
#endif

HDAPI HHD HDAPIENTRY hdInitDevice(HDstring pConfigName);
HDAPI void HDAPIENTRY hdMakeCurrentDevice(HHD hHD);
HDAPI void HDAPIENTRY hdDisableDevice(HHD hHD);
HDAPI HHD HDAPIENTRY hdGetCurrentDevice(void);

HDAPI void HDAPIENTRY hdBeginFrame(HHD hHD);
HDAPI void HDAPIENTRY hdEndFrame(HHD hHD);

HDAPI HDErrorInfo HDAPIENTRY hdGetError(void);
#define HD_DEVICE_ERROR(X) (((X).errorCode) != HD_SUCCESS)
HDAPI HDstring HDAPIENTRY hdGetErrorString(HDerror errorCode);

HDAPI void HDAPIENTRY hdEnable(HDenum cap);
HDAPI void HDAPIENTRY hdDisable(HDenum cap);
HDAPI HDboolean HDAPIENTRY hdIsEnabled(HDenum cap);

HDAPI void HDAPIENTRY hdGetBooleanv(HDenum pname, HDboolean *params);
HDAPI void HDAPIENTRY hdGetIntegerv(HDenum pname, HDint *params);
HDAPI void HDAPIENTRY hdGetFloatv(HDenum pname, HDfloat *params);
HDAPI void HDAPIENTRY hdGetDoublev(HDenum pname, HDdouble *params);
HDAPI void HDAPIENTRY hdGetLongv(HDenum pname, HDlong *params);
HDAPI HDstring HDAPIENTRY hdGetString(HDenum pname);

HDAPI void HDAPIENTRY hdSetBooleanv(HDenum pname, const HDboolean *params);
HDAPI void HDAPIENTRY hdSetIntegerv(HDenum pname, const HDint *params);
HDAPI void HDAPIENTRY hdSetFloatv(HDenum pname, const HDfloat *params);
HDAPI void HDAPIENTRY hdSetDoublev(HDenum pname, const HDdouble *params);
HDAPI void HDAPIENTRY hdSetLongv(HDenum pname, const HDlong *params);

HDAPI HDenum HDAPIENTRY hdCheckCalibration(void);
HDAPI HDenum HDAPIENTRY hdCheckCalibrationStyle(void);
HDAPI void HDAPIENTRY hdUpdateCalibration(HDenum style);

#ifdef __cplusplus
}
#endif

#endif /* HD_DEVICE_H_DEFINE */
