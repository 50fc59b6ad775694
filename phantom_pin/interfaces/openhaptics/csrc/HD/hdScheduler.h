/* phantom_pin's stand-in for OpenHaptics' libHD: the servo loop's scheduler, with OpenHaptics
 * 3.x's types, values and signatures (its HD/hdScheduler.h, as the public sources of
 * docs/servo-loop.md give them). The stand-in runs every scheduled callback once per tick in
 * its own thread, highest priority first, at HD_UPDATE_RATE (1000 Hz by default). */
#ifndef HD_SCHEDULER_H_DEFINE
#define HD_SCHEDULER_H_DEFINE

#include <HD/hdExport.h>
#include <HD/hdCompilerConfig.h>
#include <HD/hdDefines.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef unsigned int HDCallbackCode;
#define HD_CALLBACK_DONE     0
#define HD_CALLBACK_CONTINUE 1

typedef unsigned long HDSchedulerHandle;
typedef HDCallbackCode (HDCALLBACK *HDSchedulerCallback)(void *pUserData);

typedef unsigned int HDWaitCode;
#define HD_WAIT_CHECK_STATUS 0
#define HD_WAIT_INFINITE     1

HDAPI void HDAPIENTRY hdStartScheduler(void);
HDAPI void HDAPIENTRY hdStopScheduler(void);
HDAPI void HDAPIENTRY hdSetSchedulerRate(HDulong nRate);
HDAPI void HDAPIENTRY hdScheduleSynchronous(HDSchedulerCallback pCallback, void *pUserData, HDushort nPriority);
HDAPI HDSchedulerHandle HDAPIENTRY hdScheduleAsynchronous(HDSchedulerCallback pCallback, void *pUserData,
                                                          HDushort nPriority);
HDAPI void HDAPIENTRY hdUnschedule(HDSchedulerHandle hHandle);
HDAPI HDboolean HDAPIENTRY hdWaitForCompletion(HDSchedulerHandle hHandle, HDWaitCode param);
HDAPI HDdouble HDAPIENTRY hdGetSchedulerTimeStamp(void);

#ifdef __cplusplus
}
#endif

#endif /* HD_SCHEDULER_H_DEFINE */
