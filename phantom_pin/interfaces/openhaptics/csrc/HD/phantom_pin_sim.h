/* phantom_pin's stand-in for OpenHaptics' libHD: what a test does that a hand would (not
 * part of the HDAPI; a program that uses these is not an OpenHaptics program: guard them
 * with #ifdef PHANTOM_PIN_SIM). */
#ifndef PHANTOM_PIN_SIM
#define PHANTOM_PIN_SIM 1

#include <HD/hd.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The hand's force on the stylus from the next tick on (N, OpenHaptics' axes, at the gimbal
 * centre), held until set again; zero at the start. Not clamped: it is not the motors'. A
 * non-finite force is refused (HD_INVALID_VALUE) and the previous one kept. */
HDAPI void HDAPIENTRY phantomPinSimSetHandForce(const HDdouble force[3]);
/* The buttons' bit mask that HD_CURRENT_BUTTONS reads from the next tick on (HD_DEVICE_BUTTON_1...). */
HDAPI void HDAPIENTRY phantomPinSimSetButtons(HDint buttons);
/* The servo ticks run since hdStartScheduler first ran. */
HDAPI HDulong HDAPIENTRY phantomPinSimTicks(void);

#ifdef __cplusplus
}
#endif

#endif /* PHANTOM_PIN_SIM */
