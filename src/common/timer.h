/* Internal timing helpers (seconds). Not part of the public API. */
#ifndef FESD_COMMON_TIMER_H
#define FESD_COMMON_TIMER_H
/* Wall clock (CLOCK_MONOTONIC), seconds. */
double fesd__wall_time(void);
/* CPU time of the calling thread (CLOCK_THREAD_CPUTIME_ID), seconds. */
double fesd__thread_cpu_time(void);
#endif
