// clearance.work: the work done on a model by each kind of force, integrated step by step.
//
// A MuJoCo engine plugin (capability mjPLUGIN_SENSOR, needstage acc), one instance per model, no
// attributes. MuJoCo has energy sensors for the kinetic and the potential energy (gravity and
// springs) but none for the work of the forces that change them; this plugin measures those, so
// that an energy balance can be closed from sensors inside mujoco.rollout. For every step it
// records, per kind of force f (a generalized force, nv),
//   W_f += h * f_eff . (v_k + v_{k+1}) / 2
// with v_k the velocity at the step's start, v_{k+1} the integrated one and f_eff the force the
// integrator applied over the step. For Euler and implicitfast M_k (v_{k+1} - v_k) = h sum_f f_eff
// exactly (M_k the mass matrix with armature at the step's start; sum_f including the bias forces
// -qfrc_bias, which do no recorded work), so the recorded works add up to the change of
// (1/2) v' M_k v over the step, bias work included (tests/test_energy.py checks this to rounding in
// a Python step loop). The kinetic energy then changes by the works to within the change of M over
// the step and the Coriolis forces' O(h^2) work, and the potential energies by the work of their
// forces to O(h^2) per step, which makes the balance first order in h, like the integrator (under
// implicit the integrator also treats the Coriolis forces' derivative implicitly, a part no slot
// carries: O(h^2) per step as well). Cost: 0.22-0.27 us per step (two- and three-loop mechanisms,
// rollout, one thread).
//
// Kinds of force (the slots of the state and of the sensor):
//   actuator          qfrc_actuator. Under implicit and implicitfast the integrator treats the
//                     actuators' velocity derivative implicitly: the force it applies is
//                     F + (dF/dV)(V_{k+1} - V_k) per actuator output, V = moment . v (moment at the
//                     step's start), with dF/dV = biasprm[2] (affine bias) + gainprm[2] * (ctrl, or
//                     the last activation) (affine gain), as mjd_actuator_vel computes it; an
//                     actuator whose force is clamped by its forcerange gets no correction, and
//                     other gain and bias types (muscle, DC motor, ...) are not corrected.
//   equality          J_eq' efc_force over the equality rows (connect, weld, joint equalities ...)
//   contact           J_c' efc_force over the contact rows (frictionless, pyramidal, elliptic)
//   other constraint  the remaining rows of qfrc_constraint: joint and tendon limits, friction loss
//   damper            qfrc_damper + qfrc_fluid + qfrc_adhesion + qfrc_gravcomp (when not applied
//                     through actuators): MuJoCo's own non-conservative passive forces. Linear dof
//                     damping integrated implicitly (implicit, implicitfast, and Euler unless
//                     eulerdamp is disabled) is corrected like the actuators' (-B (v_{k+1} - v_k));
//                     polynomial and actuator damping are not.
//   plugin passive    qfrc_passive minus the above and qfrc_spring: the passive forces of engine
//                     plugins (the clearance.journal_bearing contacts) and of mjcb_passive.
// Springs (qfrc_spring) do no recorded work: their energy is in MuJoCo's potential energy, like
// gravity's (qfrc_bias). RK4 re-evaluates the forces within the step; the works use the step's
// first evaluation, so they are first order in h there too (not fourth).
//
// Timing. `compute` runs in mj_sensorAcc, once per mj_step at the step's start state: it keeps
// v_k and the forces in a per-mjData cache (d->plugin_data) and writes the sensor. `advance` runs
// once per mj_step after integration: if the cache was made at the step's start (time + timestep
// == new d->time) it adds the step's works to the state and counts the step; otherwise (sensors
// disabled, a hand-made state) it records nothing and the step count shows it. Sensor row i of a
// rollout (state at t_i) therefore reports the works of steps 0 .. i-1, i.e. from t_0 to t_i.
//
// State (nstate = 7, part of mjSTATE_PLUGIN, so it travels through rollout chunks):
//   [0] actuator work [J]        [1] equality work [J]        [2] contact work [J]
//   [3] other constraint work [J] [4] damper work [J]          [5] plugin passive work [J]
//   [6] steps recorded
// Sensor output (nsensordata = 8): [0..5] the works as in the state, [6] constraint power now,
// sum_i efc_force[i] efc_vel[i] = qfrc_constraint . qvel [W], [7] steps recorded.
// Work done ON the model is positive (a dissipative force's work is negative).

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <mujoco/mjplugin.h>
#include <mujoco/mujoco.h>

#include "plugin_util.h"

#define WM_NAME "clearance.work"
#define WM_NWORK 6
#define WM_NSTATE (WM_NWORK + 1)
#define WM_NSENSOR (WM_NWORK + 2)

enum { W_ACT = 0, W_EQ, W_CON, W_OTHER, W_DAMP, W_PLUGIN };

// per-mjData cache: the step-start velocity and the forces of each kind (nv each)
typedef struct {
  mjtNum time;  // d->time of the cached evaluation
  int valid;
  int nv;
  int nsensor;
  int* sensor_adr;
  mjtNum* qvel;             // v_k
  mjtNum* force[WM_NWORK];  // f of each kind at the step's start
  mjtNum* block;            // one allocation for the arrays above
} wmData;

static int wm_nstate(const mjModel* m, int instance) {
  return WM_NSTATE;
}

static int wm_nsensordata(const mjModel* m, int instance, int sensor_id) {
  return WM_NSENSOR;
}

static void wm_free(wmData* c) {
  if (c) {
    free(c->block);
    free(c->sensor_adr);
    free(c);
  }
}

static int wm_init(const mjModel* m, mjData* d, int instance) {
  int nv = (int)m->nv;
  wmData* c = (wmData*)calloc(1, sizeof(wmData));
  if (!c) {
    mju_warning(WM_NAME " instance %d: out of memory", instance);
    return -1;
  }
  c->nv = nv;
  c->block = (mjtNum*)calloc((size_t)(WM_NWORK + 1) * (nv > 0 ? nv : 1), sizeof(mjtNum));
  c->sensor_adr = cl_instance_sensors(m, instance, &c->nsensor);
  if (!c->block || !c->sensor_adr) {
    wm_free(c);
    mju_warning(WM_NAME " instance %d: out of memory", instance);
    return -1;
  }
  c->qvel = c->block;
  for (int f = 0; f < WM_NWORK; f++) {
    c->force[f] = c->block + (size_t)(f + 1) * nv;
  }
  d->plugin_data[instance] = (uintptr_t)c;
  return 0;
}

static void wm_destroy(mjData* d, int instance) {
  wm_free((wmData*)d->plugin_data[instance]);
  d->plugin_data[instance] = 0;
}

static void wm_copy(mjData* dest, const mjModel* m, const mjData* src, int instance) {
  wmData* to = (wmData*)dest->plugin_data[instance];
  const wmData* from = (const wmData*)src->plugin_data[instance];
  if (to && from) {
    mju_copy(to->block, from->block, (WM_NWORK + 1) * m->nv);
    to->time = from->time;
    to->valid = from->valid;
  }
}

static void wm_reset(const mjModel* m, mjtNum* plugin_state, void* plugin_data, int instance) {
  mju_zero(plugin_state, WM_NSTATE);
  if (plugin_data) {
    ((wmData*)plugin_data)->valid = 0;
  }
}

// res = J' efc_force over the rows whose type is in [lo, hi]; 0 if there are none
static int constraint_force(const mjModel* m, mjData* d, int lo, int hi, mjtNum* res) {
  int nefc = d->nefc, any = 0;
  for (int i = 0; i < nefc && !any; i++) {
    any = d->efc_type[i] >= lo && d->efc_type[i] <= hi;
  }
  if (!any) {
    mju_zero(res, m->nv);
    return 0;
  }
  mj_markStack(d);
  mjtNum* f = mj_stackAllocNum(d, nefc);
  for (int i = 0; i < nefc; i++) {
    f[i] = (d->efc_type[i] >= lo && d->efc_type[i] <= hi) ? d->efc_force[i] : 0.0;
  }
  mj_mulJacTVec(m, d, res, f);
  mj_freeStack(d);
  return 1;
}

static void wm_compute(const mjModel* m, mjData* d, int instance, int capability_bit) {
  wmData* c = (wmData*)d->plugin_data[instance];
  const mjtNum* s = d->plugin_state + m->plugin_stateadr[instance];
  int nv = m->nv;

  // cache the step-start velocity and forces
  mju_copy(c->qvel, d->qvel, nv);
  mju_copy(c->force[W_ACT], d->qfrc_actuator, nv);
  constraint_force(m, d, mjCNSTR_EQUALITY, mjCNSTR_EQUALITY, c->force[W_EQ]);
  constraint_force(m, d, mjCNSTR_CONTACT_FRICTIONLESS, mjCNSTR_CONTACT_ELLIPTIC, c->force[W_CON]);
  mjtNum* other = c->force[W_OTHER];
  mjtNum* damp = c->force[W_DAMP];
  mjtNum* plug = c->force[W_PLUGIN];
  for (int i = 0; i < nv; i++) {
    other[i] = d->qfrc_constraint[i] - c->force[W_EQ][i] - c->force[W_CON][i];
    damp[i] = d->qfrc_damper[i] + d->qfrc_fluid[i] + d->qfrc_adhesion[i];
    if (!m->jnt_actgravcomp[m->dof_jntid[i]]) {
      damp[i] += d->qfrc_gravcomp[i];
    }
    plug[i] = d->qfrc_passive[i] - d->qfrc_spring[i] - damp[i];
  }
  c->time = d->time;
  c->valid = 1;

  if (capability_bit & mjPLUGIN_SENSOR) {
    mjtNum out[WM_NSENSOR];
    mju_copy(out, s, WM_NWORK);
    out[WM_NWORK] = mju_dot(d->qfrc_constraint, d->qvel, nv);
    out[WM_NWORK + 1] = s[WM_NWORK];
    for (int i = 0; i < c->nsensor; i++) {
      mju_copy(d->sensordata + c->sensor_adr[i], out, WM_NSENSOR);
    }
  }
}

// an actuator switched off by its group (opt.disableactuator), as mj_actuatorDisabled says
static int actuator_off(const mjModel* m, int i) {
  int group = m->actuator_group[i];
  return group >= 0 && group <= 30 && (m->opt.disableactuator & (1 << group));
}

// extra work of the actuators' implicit velocity derivative over the step (implicit and
// implicitfast only): sum over outputs of (dF/dV) (V_{k+1} - V_k) V_mid, times h
static mjtNum actuator_implicit_work(const mjModel* m, const mjData* d, const mjtNum* dv,
                                     const mjtNum* vmid) {
  if (mjDISABLED(mjDSBL_ACTUATION)) {
    return 0;
  }
  mjtNum work = 0;
  for (int i = 0; i < m->nactuator; i++) {
    int oadr = m->actuator_outadr[i];
    if (actuator_off(m, i) || m->actuator_plugin[i] >= 0) {
      continue;
    }
    if (m->actuator_forcelimited[i] && m->actuator_outnum[i] == 1) {
      const mjtNum* range = m->actuator_forcerange + 2 * i;
      mjtNum force = d->actuator_force[oadr];
      if (force <= range[0] || force >= range[1]) {
        continue;
      }
    }
    mjtNum dfdv = 0;
    if (m->actuator_biastype[i] == mjBIAS_AFFINE) {
      dfdv += m->actuator_biasprm[mjNBIAS * i + 2];
    }
    if (m->actuator_gaintype[i] == mjGAIN_AFFINE) {
      mjtNum gv = m->actuator_gainprm[mjNGAIN * i + 2];
      if (m->actuator_dyntype[i] == mjDYN_NONE) {
        dfdv += gv * d->ctrl[m->actuator_ctrladr[i]];
      } else {
        dfdv += gv * d->act[m->actuator_actadr[i] + m->actuator_actnum[i] - 1];
      }
    }
    if (dfdv == 0) {
      continue;
    }
    for (int k = oadr; k < oadr + m->actuator_outnum[i]; k++) {
      int adr = d->moment_rowadr[k], nnz = d->moment_rownnz[k];
      mjtNum ddv = 0, vm = 0;
      for (int j = 0; j < nnz; j++) {
        int col = d->moment_colind[adr + j];
        ddv += d->actuator_moment[adr + j] * dv[col];
        vm += d->actuator_moment[adr + j] * vmid[col];
      }
      work += dfdv * ddv * vm;
    }
  }
  return m->opt.timestep * work;
}

// extra work of linear dof damping integrated implicitly: -B (v_{k+1} - v_k) . v_mid, times h
static mjtNum damping_implicit_work(const mjModel* m, const mjtNum* dv, const mjtNum* vmid) {
  int integrator = m->opt.integrator;
  if (mjDISABLED(mjDSBL_DAMPER) ||
      !(integrator == mjINT_IMPLICIT || integrator == mjINT_IMPLICITFAST ||
        (integrator == mjINT_EULER && !mjDISABLED(mjDSBL_EULERDAMP)))) {
    return 0;
  }
  mjtNum work = 0;
  for (int i = 0; i < m->nv; i++) {
    work -= m->dof_damping[i] * dv[i] * vmid[i];
  }
  return m->opt.timestep * work;
}

// once per step, after integration: add the step's works
static void wm_advance(const mjModel* m, mjData* d, int instance) {
  wmData* c = (wmData*)d->plugin_data[instance];
  mjtNum* s = d->plugin_state + m->plugin_stateadr[instance];
  mjtNum h = m->opt.timestep;
  if (!c->valid || !cl_one_step_after(d->time, c->time, h)) {
    c->valid = 0;
    return;  // no evaluation at this step's start: nothing to record
  }
  int nv = m->nv;
  mj_markStack(d);
  mjtNum* vmid = mj_stackAllocNum(d, nv);
  mjtNum* dv = mj_stackAllocNum(d, nv);
  for (int i = 0; i < nv; i++) {
    vmid[i] = 0.5 * (c->qvel[i] + d->qvel[i]);
    dv[i] = d->qvel[i] - c->qvel[i];
  }
  for (int f = 0; f < WM_NWORK; f++) {
    s[f] += h * mju_dot(c->force[f], vmid, nv);
  }
  int integrator = m->opt.integrator;
  if (integrator == mjINT_IMPLICIT || integrator == mjINT_IMPLICITFAST) {
    s[W_ACT] += actuator_implicit_work(m, d, dv, vmid);
  }
  s[W_DAMP] += damping_implicit_work(m, dv, vmid);
  s[WM_NWORK] += 1.0;
  mj_freeStack(d);
  c->valid = 0;
}


//---------------------------------- registration --------------------------------------------------

void cl_register_work_meter(void) {
  mjpPlugin work;
  mjp_defaultPlugin(&work);
  work.name = WM_NAME;
  work.capabilityflags |= mjPLUGIN_SENSOR;
  work.needstage = mjSTAGE_ACC;
  work.nattribute = 0;
  work.attributes = NULL;
  work.nstate = wm_nstate;
  work.nsensordata = wm_nsensordata;
  work.init = wm_init;
  work.destroy = wm_destroy;
  work.copy = wm_copy;
  work.reset = wm_reset;
  work.compute = wm_compute;
  work.advance = wm_advance;
  mjp_registerPlugin(&work);
}
