// What the engine plugins of this library share: attribute parsing with messages that name the
// plugin, the sampled-history tests of the in-step treatments, the per-mjData evaluation cache,
// the sensor addresses of an instance, and the exponential means of a damped rate over a step.
// (The plugins themselves: journal_bearing.c, work_meter.c, backlash_stop.c; registration in
// clearance_contact.c.)

#ifndef CLEARANCE_PLUGIN_UTIL_H_
#define CLEARANCE_PLUGIN_UTIL_H_

#include <stddef.h>

#include <mujoco/mjplugin.h>
#include <mujoco/mujoco.h>

#define CL_NCACHE 3  // RK4 evaluates the passive force at t, t + h/2 (twice) and t + h

// the name of the plugin an instance belongs to (for messages)
const char* cl_plugin_name(const mjModel* m, int instance);

// attribute string, or NULL when absent or blank
const char* cl_attr(const mjModel* m, int instance, const char* name);

// parse a finite number filling the whole string (surrounding blanks allowed); 0 on failure
int cl_parse_number(const char* text, mjtNum* out);

// read a number attribute; use *fallback when absent (required if fallback is NULL)
int cl_read_number(const mjModel* m, int instance, const char* name, const mjtNum* fallback,
                   mjtNum* out);

// ok, or a warning naming the attribute, its value and what was expected
int cl_check(const mjModel* m, int ok, int instance, const char* name, mjtNum value,
             const char* expected);

// read a site-name attribute into its id
int cl_read_site(const mjModel* m, int instance, const char* name, int* site);

// 1 for the semi-implicit integrators (Euler, implicit, implicitfast), whose sampled velocity
// lags its position by half a step; 0 for RK4
int cl_semi_implicit(const mjModel* m);

// 1 if time t is one step h after time t0 (to rounding: the engine adds h to the time)
int cl_one_step_after(mjtNum t, mjtNum t0, mjtNum h);

// 1 if a sample recorded at `sample_time` (`have` != 0: recorded at all) is one step old
int cl_is_last_step(const mjModel* m, const mjData* d, mjtNum have, mjtNum sample_time);

// 1 if such a sample is recent enough to locate an onset (RK4 stages reach 2 steps)
int cl_is_recent(const mjModel* m, const mjData* d, mjtNum have, mjtNum sample_time);

// The per-mjData evaluation caches of the passive plugins hold structs that begin with
// (mjtNum time; int valid;). cl_cache_slot picks where an evaluation at `time` goes: the slot
// already holding that time, else a free one, else the next in round-robin order.
typedef struct {
  mjtNum time;
  int valid;
} clEvalHead;

int cl_cache_slot(const void* cache, size_t stride, int n, mjtNum time, int* next);

// the cached evaluation made one step h before `time` (the step's start), or NULL
const void* cl_cache_step_start(const void* cache, size_t stride, int n, mjtNum time, mjtNum h);

// the sensordata addresses of a plugin instance's sensors: a malloc'd array (at least one
// element, so that NULL means out of memory) and their count in *n
int* cl_instance_sensors(const mjModel* m, int instance, int* n);

// phi1(-g) = (1 - exp(-g)) / g and psi(g) = (g - 1 + exp(-g)) / g^2 for g >= 0: the mean of
// r(t) over a step h for r' = A - (g / h) r, r(0) = r0, is r0 phi1(-g) + h A psi(g)
void cl_exponential_means(mjtNum g, mjtNum* phi1, mjtNum* psi);

// registration of each plugin of the library
void cl_register_journal_bearing(void);
void cl_register_work_meter(void);
void cl_register_backlash_stop(void);
void cl_register_slider_guide(void);

#endif  // CLEARANCE_PLUGIN_UTIL_H_
