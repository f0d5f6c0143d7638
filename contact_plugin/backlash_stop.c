// clearance.backlash_stop: the stop at the ends of a backlash band, the gear mesh's impact law.
//
// A MuJoCo engine plugin (capabilities mjPLUGIN_PASSIVE | mjPLUGIN_SENSOR, needstage vel), one
// instance per band. A hinge with backlash (clearance.retrofit.backlash) is a load hinge (the
// link) and a motor hinge on the same axis; the load may turn within +-b of the motor. With
//   r = q_load - q_motor      (the two hinges' qpos), s = sign(r) (the side of the band)
//   delta = |r| - b            angular penetration past the band [rad] (negative: inside)
//   delta_dot = s (v_load - v_motor)   its rate [rad/s] (> 0 closing)
// the stop's torque is the angular Lankarani-Nikravesh law of laws.mesh_torque, reproduced
// operation by operation:
//   T = max(K delta^n (1 + chi (delta_dot / v_in)), 0) for delta > 0, else 0,
//   chi = 3 (1 - e^2) / 4
// and it is applied as passive generalized forces: -s T on the load dof and +s T on the motor
// dof (the teeth push the two sides apart, back into the band). No tendon limit and no
// constraint row is involved: the stop is the law itself, at whatever inertia the pose gives.
// The approach speed v_in is recorded at onset and kept for the impact, the onset located inside
// the step, as for clearance.journal_bearing (see its header above); the evaluation cache and
// `advance` work as there. The in-step treatment is simpler: delta_dot = s (v_load - v_motor) has
// a constant Jacobian (no kinematic part), so for the semi-implicit integrators the whole sampled
// rate lags half a step, and it is advanced by half a step with its change extrapolated from the
// last two steps,
//   x_law = x_k + (x_k - x_{k-1}) - (x_{k-1} - x_{k-2}) / 2
// (with one recorded step only x_k + (x_k - x_{k-1}) / 2; with none, x_k), and the onset rate
// is interpolated at theta + 1/2. A sample taken on the other side of the band is no history
// (the rate changes sign at r = 0).
//
// State (nstate = 11 mjtNums per instance):
//   [0] time of the last recorded sample [s]    [1] delta there [rad]
//   [2] geometric delta_dot there [rad/s]       [3] the same one step earlier [rad/s]
//   [4] side s of the band there (+1, -1, 0)    [5] peak T of the current or last impact [N m]
//   [6] recorded samples one step apart: 0, 1 or 2
//   [7] 1 while in an impact, else 0            [8] approach speed of that impact [rad/s]
//   [9] dissipated work so far [J]              [10] number of recorded steps
//
// Sensor output (nsensordata = 8), evaluated at the current state:
//   [0] T stop torque [N m] (>= 0)    [1] -s T, the torque on the load hinge [N m]
//   [2] delta [rad]                   [3] delta_dot entering the law [rad/s] (> 0 closing)
//   [4] v_in approach speed [rad/s] (0 out of contact)
//   [5] potential energy K delta^(n+1) / (n+1) [J] (0 for delta <= 0)
//   [6] work dissipated by the stop so far [J] (>= 0)
//   [7] peak T of the current impact, or of the last one once it has ended [N m]
//
// Config attributes (strings; validated in Python before compiling, re-checked here):
//   load_joint, motor_joint   names of two distinct hinges
//   half_width b [rad] > 0
//   stiffness K [N m/rad^n] > 0, exponent n > 0 (default 1, a gear mesh)
//   restitution e in [0, 1]
//   min_approach_speed [rad/s] > 0 (default 1e-3, laws.MIN_APPROACH_SPEED)

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <mujoco/mjplugin.h>
#include <mujoco/mujoco.h>

#include "contact_laws.h"
#include "plugin_util.h"

// state layout of a backlash stop
enum {
  S_TIME = 0, S_DELTA, S_RATE, S_RATE2, S_VT, S_VT2, S_HAVE, S_CONTACT, S_VIN, S_WORK,
  S_NSTEP, S_COUNT
};

// the stop's sample tests (its state layout: S_HAVE, S_TIME)
static int sample_is_last_step(const mjModel* m, const mjData* d, const mjtNum* s) {
  return cl_is_last_step(m, d, s[S_HAVE], s[S_TIME]);
}

static int sample_is_recent(const mjModel* m, const mjData* d, const mjtNum* s) {
  return cl_is_recent(m, d, s[S_HAVE], s[S_TIME]);
}

// a sampled velocity x advanced by half a step, from the samples x1, x2 one and two steps back
// (semi-implicit integrators only): the stop's rate has a constant Jacobian, so the whole
// change of x is the change of the generalized velocities
static mjtNum half_step_ahead(const mjModel* m, const mjData* d, const mjtNum* s,
                              mjtNum x, mjtNum x1, mjtNum x2) {
  if (!cl_semi_implicit(m) || !sample_is_last_step(m, d, s)) {
    return x;
  }
  mjtNum change = x - x1;  // h times the last step's acceleration
  if (s[S_HAVE] >= 2) {
    change += change - (x1 - x2);  // extrapolated to this step
  }
  return x + 0.5 * change;
}

#define BS_NAME "clearance.backlash_stop"
#define BS_NSENSOR 8

enum { S_SIDE = S_VT, S_PEAK = S_VT2 };

static const char* const kStopAttributes[] = {
  "load_joint", "motor_joint", "half_width", "stiffness", "exponent", "restitution",
  "min_approach_speed"
};

typedef struct {
  mjtNum time;      // d->time of the evaluation
  int valid;        // 1 if this cache slot holds an evaluation
  mjtNum delta;     // penetration [rad]
  mjtNum rate_geo;  // geometric penetration rate [rad/s]
  mjtNum rate;      // rate entering the law [rad/s]
  mjtNum side;      // s = sign(q_load - q_motor)
  mjtNum vin;       // approach speed [rad/s] (0 out of contact)
  mjtNum torque;    // T [N m]
  mjtNum tel;       // elastic part K delta^n [N m]
  mjtNum power;     // dissipated power [W]
} bsEval;

typedef struct {
  int load_qpos, motor_qpos, load_dof, motor_dof;
  mjtNum half_width, stiffness, exponent, restitution, chi, min_speed;
  int nsensor;
  int* sensor_adr;
  bsEval cache[CL_NCACHE];
  int cache_next;
} bsData;

static int read_hinge(const mjModel* m, int instance, const char* name, int* qpos, int* dof) {
  const char* text = cl_attr(m, instance, name);
  int j = text ? mj_name2id(m, mjOBJ_JOINT, text) : -1;
  if (j < 0 || m->jnt_type[j] != mjJNT_HINGE) {
    mju_warning(BS_NAME " instance %d: attribute '%s' = '%s', expected the name of a hinge",
                instance, name, text ? text : "");
    return 0;
  }
  *qpos = m->jnt_qposadr[j];
  *dof = m->jnt_dofadr[j];
  return 1;
}

static int bs_configure(const mjModel* m, int instance, bsData* c) {
  static const mjtNum kOne = 1.0, kMinSpeed = 1e-3;
  if (!read_hinge(m, instance, "load_joint", &c->load_qpos, &c->load_dof) ||
      !read_hinge(m, instance, "motor_joint", &c->motor_qpos, &c->motor_dof)) {
    return 0;
  }
  if (c->load_dof == c->motor_dof) {
    mju_warning(BS_NAME " instance %d: load_joint and motor_joint are the same hinge", instance);
    return 0;
  }
  if (!cl_read_number(m, instance, "half_width", NULL, &c->half_width) ||
      !cl_check(m, c->half_width > 0, instance, "half_width", c->half_width, "> 0 [rad]") ||
      !cl_read_number(m, instance, "stiffness", NULL, &c->stiffness) ||
      !cl_check(m, c->stiffness > 0, instance, "stiffness", c->stiffness, "> 0 [N m/rad^n]") ||
      !cl_read_number(m, instance, "exponent", &kOne, &c->exponent) ||
      !cl_check(m, c->exponent > 0, instance, "exponent", c->exponent, "> 0") ||
      !cl_read_number(m, instance, "restitution", NULL, &c->restitution) ||
      !cl_check(m, c->restitution >= 0 && c->restitution <= 1, instance, "restitution",
             c->restitution, "in [0, 1]") ||
      !cl_read_number(m, instance, "min_approach_speed", &kMinSpeed, &c->min_speed) ||
      !cl_check(m, c->min_speed > 0, instance, "min_approach_speed", c->min_speed, "> 0 [rad/s]")) {
    return 0;
  }
  c->chi = cl_hysteresis(LAW_LN, c->restitution);
  return 1;
}

// evaluate the stop at the current state of d; pure in (d, state)
static void bs_evaluate(const mjModel* m, const mjData* d, const bsData* c, const mjtNum* s,
                        bsEval* ev) {
  mjtNum r = d->qpos[c->load_qpos] - d->qpos[c->motor_qpos];
  mjtNum side = r > 0 ? 1.0 : (r < 0 ? -1.0 : 0.0);
  mjtNum delta = mju_abs(r) - c->half_width;
  mjtNum rate_geo = side * (d->qvel[c->load_dof] - d->qvel[c->motor_dof]);

  // a sample from the other side of the band is no history
  int same_side = s[S_SIDE] == side;
  mjtNum rate = same_side ? half_step_ahead(m, d, s, rate_geo, s[S_RATE], s[S_RATE2]) : rate_geo;

  mjtNum vin = 0;
  if (delta > 0) {
    if (s[S_CONTACT] != 0 && same_side) {
      vin = s[S_VIN];
    } else if (same_side && sample_is_recent(m, d, s) && s[S_DELTA] <= 0) {
      mjtNum theta = s[S_DELTA] / (s[S_DELTA] - delta);
      mjtNum w = (cl_semi_implicit(m) && sample_is_last_step(m, d, s)) ? theta + 0.5 : theta;
      vin = s[S_RATE] + w * (rate_geo - s[S_RATE]);
    } else {
      vin = rate;
    }
    vin = vin > c->min_speed ? vin : c->min_speed;
  }

  mjtNum tel = 0, torque = 0;
  if (delta > 0) {
    tel = c->stiffness * pow(delta, c->exponent);
    torque = tel * (1.0 + c->chi * (rate / vin));
    torque = torque > 0 ? torque : 0.0;
  }
  ev->time = d->time;
  ev->valid = 1;
  ev->delta = delta;
  ev->rate_geo = rate_geo;
  ev->rate = rate;
  ev->side = side;
  ev->vin = vin;
  ev->torque = torque;
  ev->tel = tel;
  ev->power = delta > 0 ? (torque - tel) * rate : 0.0;
}

static int bs_nstate(const mjModel* m, int instance) {
  return S_COUNT;
}

static int bs_nsensordata(const mjModel* m, int instance, int sensor_id) {
  return BS_NSENSOR;
}

static int bs_init(const mjModel* m, mjData* d, int instance) {
  bsData* c = (bsData*)calloc(1, sizeof(bsData));
  if (!c) {
    mju_warning(BS_NAME " instance %d: out of memory", instance);
    return -1;
  }
  if (!bs_configure(m, instance, c)) {
    free(c);
    return -1;
  }
  c->sensor_adr = cl_instance_sensors(m, instance, &c->nsensor);
  if (!c->sensor_adr) {
    free(c);
    mju_warning(BS_NAME " instance %d: out of memory", instance);
    return -1;
  }
  d->plugin_data[instance] = (uintptr_t)c;
  return 0;
}

static void bs_destroy(mjData* d, int instance) {
  bsData* c = (bsData*)d->plugin_data[instance];
  if (c) {
    free(c->sensor_adr);
    free(c);
  }
  d->plugin_data[instance] = 0;
}

static void bs_copy(mjData* dest, const mjModel* m, const mjData* src, int instance) {
  bsData* to = (bsData*)dest->plugin_data[instance];
  const bsData* from = (const bsData*)src->plugin_data[instance];
  if (to && from) {
    memcpy(to->cache, from->cache, sizeof(to->cache));
    to->cache_next = from->cache_next;
  }
}

static void bs_clear_cache(bsData* c) {
  for (int i = 0; i < CL_NCACHE; i++) {
    c->cache[i].valid = 0;
  }
  c->cache_next = 0;
}

static void bs_reset(const mjModel* m, mjtNum* plugin_state, void* plugin_data, int instance) {
  mju_zero(plugin_state, S_COUNT);
  if (plugin_data) {
    bs_clear_cache((bsData*)plugin_data);
  }
}

static void bs_compute(const mjModel* m, mjData* d, int instance, int capability_bit) {
  bsData* c = (bsData*)d->plugin_data[instance];
  const mjtNum* s = d->plugin_state + m->plugin_stateadr[instance];
  bsEval ev;
  bs_evaluate(m, d, c, s, &ev);

  if (capability_bit & mjPLUGIN_PASSIVE) {
    c->cache[cl_cache_slot(c->cache, sizeof(bsEval), CL_NCACHE, ev.time, &c->cache_next)] = ev;
    if (ev.torque != 0) {
      d->qfrc_passive[c->load_dof] -= ev.side * ev.torque;
      d->qfrc_passive[c->motor_dof] += ev.side * ev.torque;
    }
  }

  if (capability_bit & mjPLUGIN_SENSOR) {
    mjtNum peak = ev.delta > 0 && s[S_CONTACT] != 0 ? mju_max(s[S_PEAK], ev.torque)
                                                    : (ev.delta > 0 ? ev.torque : s[S_PEAK]);
    mjtNum out[BS_NSENSOR] = {
      ev.torque, -ev.side * ev.torque, ev.delta, ev.rate, ev.vin,
      ev.delta > 0 ? ev.tel * ev.delta / (c->exponent + 1) : 0.0,
      s[S_WORK], peak
    };
    for (int i = 0; i < c->nsensor; i++) {
      mju_copy(d->sensordata + c->sensor_adr[i], out, BS_NSENSOR);
    }
  }
}

// once per step, after integration: commit the evaluation made at the step's start state
static void bs_advance(const mjModel* m, mjData* d, int instance) {
  bsData* c = (bsData*)d->plugin_data[instance];
  mjtNum* s = d->plugin_state + m->plugin_stateadr[instance];
  mjtNum h = m->opt.timestep;
  const bsEval* ev = (const bsEval*)cl_cache_step_start(c->cache, sizeof(bsEval), CL_NCACHE,
                                                      d->time, h);
  if (ev) {
    int consecutive = s[S_HAVE] != 0 && cl_one_step_after(ev->time, s[S_TIME], h) &&
                      s[S_SIDE] == ev->side;
    int onset = ev->delta > 0 && !(s[S_CONTACT] != 0 && s[S_SIDE] == ev->side);
    s[S_WORK] += h * ev->power;
    s[S_PEAK] = onset ? ev->torque : (ev->delta > 0 ? mju_max(s[S_PEAK], ev->torque) : s[S_PEAK]);
    s[S_CONTACT] = ev->delta > 0 ? 1.0 : 0.0;
    s[S_VIN] = ev->delta > 0 ? ev->vin : 0.0;
    s[S_RATE2] = consecutive ? s[S_RATE] : 0.0;
    s[S_HAVE] = consecutive ? 2.0 : 1.0;
    s[S_TIME] = ev->time;
    s[S_DELTA] = ev->delta;
    s[S_RATE] = ev->rate_geo;
    s[S_SIDE] = ev->side;
    s[S_NSTEP] += 1.0;
  }
  bs_clear_cache(c);
}


//---------------------------------- registration --------------------------------------------------

void cl_register_backlash_stop(void) {
  mjpPlugin stop;
  mjp_defaultPlugin(&stop);
  stop.name = BS_NAME;
  stop.capabilityflags |= mjPLUGIN_PASSIVE | mjPLUGIN_SENSOR;
  stop.needstage = mjSTAGE_VEL;
  stop.nattribute = sizeof(kStopAttributes) / sizeof(kStopAttributes[0]);
  stop.attributes = kStopAttributes;
  stop.nstate = bs_nstate;
  stop.nsensordata = bs_nsensordata;
  stop.init = bs_init;
  stop.destroy = bs_destroy;
  stop.copy = bs_copy;
  stop.reset = bs_reset;
  stop.compute = bs_compute;
  stop.advance = bs_advance;
  mjp_registerPlugin(&stop);
}
