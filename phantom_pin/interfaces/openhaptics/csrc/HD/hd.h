/* phantom_pin's stand-in for OpenHaptics' libHD (HDAPI): the header an OpenHaptics program
 * includes, laid out as OpenHaptics' is (HD/hd.h including the definitions, the device and
 * the scheduler's declarations). Built by `phantom-pin openhaptics-sim build DIR`; the
 * library DIR/lib/libHD.so runs the program against phantom_pin's simulated device
 * (docs/servo-loop.md: what it simulates and what it does not). */
#ifndef HD_H_DEFINE
#define HD_H_DEFINE

#include <HD/hdCompilerConfig.h>
#include <HD/hdExport.h>
#include <HD/hdDefines.h>
#include <HD/hdDevice.h>
#include <HD/hdScheduler.h>

#endif /* HD_H_DEFINE */
