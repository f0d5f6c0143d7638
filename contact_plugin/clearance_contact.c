// clearance.journal_bearing: exact journal-bearing contact of a revolute clearance joint.
// (The same library also registers clearance.work, the energy meter's work sensor, and
// clearance.backlash_stop, the gear mesh's impact law at the ends of a backlash band: see their
// sections after the journal-bearing callbacks.)
//
// A MuJoCo engine plugin (capabilities mjPLUGIN_PASSIVE | mjPLUGIN_SENSOR), one instance per
// clearance joint. It needs no collision geometry: the journal and the bearing are two circles,
// described by two sites and two radii, and the contact force is applied as a passive force.
//
// Geometry (exact circles). The journal site sits at the journal centre on the journal body, the
// bearing site at the bearing centre on the bearing body; the joint's plane is the bearing
// site's local x-y plane, its normal z the site's local z axis. With d = p_J - p_B,
//   e = d - (d.z) z           eccentricity, projected on the bearing plane
//   delta = |e| - c           penetration [m] (negative: gap), c the radial clearance
//   n = e / |e|               contact normal (bearing x axis when |e| = 0)
//   delta_dot = d|e|/dt = (e.v - (d.z)(d.(w_B x z))) / |e|, v = v_J - v_B at the two sites
//                             (the second term vanishes for planar motion)
// The contact points are P_J = p_J + R_J n on the journal and P_B = p_B + (R_J + c) n on the
// bearing surface; t = z x n, and v_t = t.(v_J(P_J) - v_B(P_B)) is the tangential velocity.
//
// Forces (contact_calibration/laws.py is the reference, reproduced operation by operation):
//   F_el = K delta^n for delta > 0, 0 otherwise
//   hertz:         F_n = F_el
//   dissipative:   F_n = max(F_el (1 + chi (delta_dot / v_in)), 0), chi(c_e) as in
//                  laws.hysteresis_factor (lankarani_nikravesh, hunt_crossley, flores,
//                  gonthier, hu_guo)
//   impact:        F_n = max(F_el + (C_max STEP(delta)) delta_dot, 0), STEP = z^2 (3 - 2z),
//                  z = clip(delta / d_max, 0, 1)
//   friction:      F_t = -mu c_d F_n sign(v_t), c_d = clip((|v_t| - v0) / (v1 - v0), 0, 1)
//                  (Ambrosio; mu = 0 gives no friction)
// The force on the journal, f = -F_n n + F_t t, is applied at P_J on the journal body and -f at
// P_B on the bearing body (mj_applyFT into qfrc_passive). A frictionless force acts along the
// line of centres, so it exerts no moment about either centre.
//
// Approach speed v_in. Recorded at contact onset and kept for the whole impact; reset when
// delta <= 0 (separation). The onset is located inside the step where delta crosses 0: delta is
// taken as linear in time between the last recorded sample and the current one, giving the
// crossing fraction theta = delta_prev / (delta_prev - delta), and the rate is interpolated
// linearly in time at the crossing between the rates at the two samples' times (see "In-step
// treatment" for those rates). v_in = max(that rate, min_approach_speed). A contact present with
// no usable history (first step after a reset, or a state set by hand) records
// max(delta_dot, min_approach_speed).
//
// In-step treatment. The force is evaluated once at the step's state (the integrator's first
// force evaluation) and held over the step. MuJoCo's Euler, implicit, implicitfast and discrete
// integrators are semi-implicit (velocities first, then positions with the new velocities): the
// positions q_k are at t_k, the velocity qvel_k is the one of the interval before t_k, and the
// step's velocity change dv carries the interval after it. A rate read from (q_k, qvel_k) is
// therefore half a step behind in its velocity part only; its kinematic part (the turning
// normal, the Jacobian's own change, J'dot qdot, of order omega^2 l on a mechanism) is at t_k
// already. So only the generalized-velocity part is advanced, along the rows J_n (normal rate)
// and J_t (tangential velocity) over the dofs at q_k:
//   dv = h M^-1 J' f  +  other     (this joint's own force f, and every other force)
// The other forces' change is taken from the last step (the recorded dv minus this joint's own
// response there, kept in the state as nv numbers), extrapolated as constant. This joint's own
// response is taken at this step, with the model's equality constraints (loop closures, a pin
// held by a connect) acting as the constraint solver solves them alone at this state:
//   W = M^-1 - Y (J_c M^-1 J_c' + R)^-1 Y',  Y = M^-1 J_c'  (J_c, R: the equality rows)
// and w_nn = J_n W J_n', w_nt = J_n W J_t', w_tt = J_t W J_t'. What the response leaves out (an
// implicit actuator's damping, contact and limit rows) makes W overstate the joint's mobility,
// never understate it; the rest comes through the constant extrapolation with one step's lag,
// which stays stable whatever share it is (measured on the scalar model of the lag: spectral
// radius below 1 for any share below 1; a linear extrapolation is not, beyond a share of 1/2).
//
// Normal force. Over the step the normal rate obeys r' = A - (g/h) r with r(0) = r0 = J_n qvel_k
// (the sampled rate), h A = J_n other - h w_nn F_el + h w_nt F_t (the other forces, the elastic
// force held, the last step's friction), and g = h w_nn C the law's damping C = dF_n/d(delta_dot)
// (chi F_el / v_in for the dissipative laws, C_max STEP(delta) for the impact law, 0 for Hertz).
// The rate entering the law is r's exact mean over the step,
//   rate = r0 phi1(-g) + h A psi(g),  phi1(-g) = (1 - e^-g)/g,  psi(g) = (g - 1 + e^-g)/g^2,
// i.e. the damping integrated exponentially: for small g it is r0 + (h/2)(A - (g/h) r0), the
// rate at the step's time; for any g (a grazing contact's damping at the 1 mm/s floor of v_in
// reaches g >> 1 at the default step) it stays bounded by r0 and the rate's change, so no
// approach speed makes the damping unstable. (An explicit damping term, advanced by
// extrapolation, is stable only for g below about 0.5; a grazing re-onset of the c = 0.1 mm
// slider-crank reaches 0.58 at 3 us.) The elastic force is held over the step, so the time-step
// rule stays a stiffness rule (omega h).
// The rate at a sample's time, for the approach speed: at the current step
// r0 + (1/2) J_n other (no own force yet at onset), at the last step r0 + (1/2) J_n dv from the
// velocity change it actually had (the mean of its start and end rates).
//
// Friction near rest. Ambrosio's ramp between v0 and v1 is stiff: explicitly it is resolved only
// while h mu F_n w_tt / (v1 - v0) < 2 (about 1 kN at 1 us, mu = 0.1, an effective tangential
// mass of 0.06 kg), and beyond that v_t chatters around 0. The friction force is therefore taken
// at the tangential velocity it leaves at the step's end,
//   v_end = v_t0 + J_t other - h w_nt F_n + h w_tt F_t(v_end),  F_t(v) = -mu F_n c_d(v) sign(v)
// (backward Euler in v_t: v + h w_tt mu F_n c_d(v) sign(v) increases with v, so the root is
// unique, and each piece of the ramp is linear, so it is solved exactly). In gross sliding
// through the step it is the sliding friction -mu F_n sign(v_t) as before; near rest v_t settles
// inside the ramp instead of changing sign every step. RK4's states are synchronous and its
// force explicit: it uses the sampled rates and velocities as they are.
//
// State (nstate = 9 + nv mjtNums per instance, part of mjSTATE_PLUGIN, so it travels with
// mj_getState/mj_setState and through mujoco.rollout chunks):
//   [0] time of the last recorded sample [s]    [1] delta there [m]
//   [2] normal rate at that sample's time [m/s] [3] friction force F_t applied there [N]
//   [4] 1 once a sample is recorded, else 0     [5] 1 while in an impact, else 0
//   [6] approach speed of that impact [m/s]     [7] dissipated work so far [J]
//   [8] number of recorded steps                [9 .. 9 + nv) the last step's velocity change
//                                                    from the other forces [m/s, rad/s]
// The state is updated once per step, in `advance` (which MuJoCo calls once per mj_step, after
// integration, whatever the integrator), from the force evaluation made at the step's start
// state and the velocities the step ended with. Because `compute` runs several times per step
// under RK4 and kinematics in mjData describe the last of those evaluations by the time
// `advance` runs, every passive evaluation is kept in a small per-mjData cache keyed by d->time
// (with the velocities, the own response and J_n it was made with); `advance` commits the one
// whose time is the step's start time (time + timestep == new d->time). `compute` never writes
// the state. The sensor stage reads the cached evaluation of the same state instead of
// evaluating it again. Setting qpos/qvel by hand in the middle of a run leaves a state that
// describes the old trajectory: reset it (mj_resetData, or zero the instance's plugin_state)
// when doing so.
//
// Sensor output (nsensordata = 8), evaluated at the current state:
//   [0] F_n normal force [N] (>= 0)   [1] F_t tangential force on the journal along t [N]
//   [2] delta penetration [m]         [3] delta_dot entering the law [m/s] (> 0 approaching)
//   [4] v_in approach speed [m/s] (0 out of contact)
//   [5] contact potential energy K delta^(n+1) / (n+1) [J] (0 for delta <= 0)
//   [6] work dissipated by the contact so far [J] (normal damping + friction; recorded once per
//       step in `advance` as timestep * power of the applied force: (F_n - F_el) rate - F_t v_t,
//       v_t the mean of the step's start and end tangential velocities)
//   [7] |e| eccentricity magnitude [m]
//
// Config attributes (strings; validated in Python before compiling, re-checked here):
//   journal_site, bearing_site  site names
//   clearance c [m] > 0, journal_radius R_J [m] > 0
//   law: hertz | lankarani_nikravesh | hunt_crossley | flores | gonthier | hu_guo | impact,
//        or its code 0..6 in that order
//   stiffness K [N/m^n] > 0, exponent n > 0 (default 1.5)
//   restitution c_e: dissipative laws only; [0, 1] for lankarani_nikravesh and hunt_crossley,
//        (0, 1] for flores, gonthier, hu_guo
//   c_max [N s/m] >= 0, d_max [m] > 0: impact law only
//   friction mu >= 0 (default 0), v0 [m/s] (default 1e-4), v1 [m/s] (default 1e-3), 0 <= v0 < v1
//   min_approach_speed [m/s] > 0 (default 1e-3, laws.MIN_APPROACH_SPEED)

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <mujoco/mjplugin.h>
#include <mujoco/mujoco.h>

#define JB_NAME "clearance.journal_bearing"
#define JB_NSENSOR 8
#define JB_NCACHE 3  // RK4 evaluates the force at t, t + h/2 (twice) and t + h

// state layout of a journal bearing (B_OTHER: nv values)
enum {
  B_TIME = 0, B_DELTA, B_RATE, B_FT, B_HAVE, B_CONTACT, B_VIN, B_WORK, B_NSTEP, B_OTHER
};

// state layout of a backlash stop
enum {
  S_TIME = 0, S_DELTA, S_RATE, S_RATE2, S_VT, S_VT2, S_HAVE, S_CONTACT, S_VIN, S_WORK,
  S_NSTEP, S_COUNT
};

// contact laws, in the order of clearance.model.ContactLaw
enum {
  LAW_HERTZ = 0, LAW_LN, LAW_HC, LAW_FLORES, LAW_GONTHIER, LAW_HU_GUO, LAW_IMPACT, LAW_COUNT
};

static const char* const kLawNames[LAW_COUNT] = {
  "hertz", "lankarani_nikravesh", "hunt_crossley", "flores", "gonthier", "hu_guo", "impact"
};

static const char* const kAttributes[] = {
  "journal_site", "bearing_site", "clearance", "journal_radius", "law", "stiffness",
  "exponent", "restitution", "c_max", "d_max", "friction", "v0", "v1", "min_approach_speed"
};

// one force evaluation
typedef struct {
  mjtNum time;       // d->time of the evaluation
  int valid;         // 1 if this cache slot holds an evaluation
  mjtNum delta;      // penetration [m]
  mjtNum rate_geo;   // geometric penetration rate [m/s]
  mjtNum rate;       // rate entering the law [m/s]
  mjtNum vt_geo;     // geometric tangential velocity [m/s]
  mjtNum vin;        // approach speed [m/s] (0 out of contact)
  mjtNum fn;         // normal force [N]
  mjtNum ft;         // tangential force [N]
  mjtNum fel;        // elastic part K delta^n [N]
  mjtNum ecc;        // |e| [m]
  mjtNum power;      // dissipated power [W]
  mjtNum normal[3];  // n (world)
  mjtNum tangent[3];  // t = z x n (world)
  mjtNum pj[3];      // contact point on the journal (world)
  mjtNum pb[3];      // contact point on the bearing (world)
} jbEval;

// parsed configuration and per-mjData scratch, in d->plugin_data[instance]
typedef struct {
  int journal_site, bearing_site;
  int journal_body, bearing_body;
  mjtNum clearance, journal_radius;
  int law;
  mjtNum stiffness, exponent, restitution, chi;
  mjtNum c_max, d_max;
  mjtNum friction, v0, v1;
  mjtNum min_speed;
  int nsensor;
  int* sensor_adr;           // sensordata addresses of this instance's sensors
  jbEval cache[JB_NCACHE];   // passive evaluations since the last advance
  int cache_next;            // round-robin slot
  // in-step treatment (semi-implicit integrators), one block of 17 + 3 JB_NCACHE times nv values
  // allocated in init (vec_t follows vec_n, ut follows un: each pair is solved in one call):
  mjtNum* vec_n;             // row of the normal rate over the dofs (nv)
  mjtNum* vec_t;             // row of the tangential velocity (nv)
  mjtNum* un;                // M^-1 vec_n' (nv)
  mjtNum* ut;                // M^-1 vec_t' (nv)
  mjtNum* own;               // this joint's velocity change over the step, h M^-1 J' f (nv)
  mjtNum* scratch;           // two bodies' Jacobians (12 nv)
  mjtNum* slot_vec;          // per cache slot: qvel, own and vec_n at the evaluation (3 nv each)
  // the equality constraints' rows, at most eq_max of them (allocated in init)
  int eq_max;
  mjtNum* eq_rows;           // their Jacobian rows (eq_max nv)
  mjtNum* eq_y;              // M^-1 of each row (eq_max nv)
  mjtNum* eq_a;              // J_c M^-1 J_c' + R, then its Cholesky factor (eq_max^2)
  mjtNum* eq_z;              // solves (2 eq_max)
} jbData;


//---------------------------------- attribute parsing ---------------------------------------------

// attribute string, or NULL when absent or blank
static const char* attr(const mjModel* m, int instance, const char* name) {
  const char* value = mj_getPluginConfig(m, instance, name);
  if (!value) {
    return NULL;
  }
  const char* p = value;
  while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r') {
    p++;
  }
  return *p ? value : NULL;
}

// parse a finite number filling the whole string (surrounding blanks allowed); 0 on failure
static int parse_number(const char* text, mjtNum* out) {
  char* end;
  double v = strtod(text, &end);
  if (end == text) {
    return 0;
  }
  while (*end == ' ' || *end == '\t' || *end == '\n' || *end == '\r') {
    end++;
  }
  if (*end || !isfinite(v)) {
    return 0;
  }
  *out = v;
  return 1;
}

// read a number attribute; use *fallback when absent (required if fallback is NULL)
static int read_number(const mjModel* m, int instance, const char* name,
                       const mjtNum* fallback, mjtNum* out) {
  const char* text = attr(m, instance, name);
  if (!text) {
    if (fallback) {
      *out = *fallback;
      return 1;
    }
    mju_warning(JB_NAME " instance %d: attribute '%s' is required", instance, name);
    return 0;
  }
  if (!parse_number(text, out)) {
    mju_warning(JB_NAME " instance %d: attribute '%s' must be a finite number, got '%s'",
                instance, name, text);
    return 0;
  }
  return 1;
}

static int check(int ok, int instance, const char* name, mjtNum value, const char* expected) {
  if (!ok) {
    mju_warning(JB_NAME " instance %d: attribute '%s' = %g, expected %s",
                instance, name, value, expected);
  }
  return ok;
}

static int read_site(const mjModel* m, int instance, const char* name, int* site) {
  const char* text = attr(m, instance, name);
  if (!text) {
    mju_warning(JB_NAME " instance %d: attribute '%s' (a site name) is required", instance, name);
    return 0;
  }
  *site = mj_name2id(m, mjOBJ_SITE, text);
  if (*site < 0) {
    mju_warning(JB_NAME " instance %d: attribute '%s': no site named '%s'", instance, name, text);
    return 0;
  }
  return 1;
}

static int read_law(const mjModel* m, int instance, int* law) {
  const char* text = attr(m, instance, "law");
  if (!text) {
    mju_warning(JB_NAME " instance %d: attribute 'law' is required", instance);
    return 0;
  }
  for (int i = 0; i < LAW_COUNT; i++) {
    if (!strcmp(text, kLawNames[i])) {
      *law = i;
      return 1;
    }
  }
  mjtNum code;
  if (parse_number(text, &code) && code == floor(code) && code >= 0 && code < LAW_COUNT) {
    *law = (int)code;
    return 1;
  }
  mju_warning(JB_NAME " instance %d: attribute 'law' = '%s', expected one of hertz, "
              "lankarani_nikravesh, hunt_crossley, flores, gonthier, hu_guo, impact or 0..6",
              instance, text);
  return 0;
}

// hysteresis factor chi(c_e), the expressions of laws.hysteresis_factor
static mjtNum hysteresis(int law, mjtNum e) {
  switch (law) {
    case LAW_LN:       return 3.0 * (1.0 - e * e) / 4.0;
    case LAW_HC:       return 1.5 * (1.0 - e);
    case LAW_FLORES:   return 8.0 * (1.0 - e) / (5.0 * e);
    case LAW_GONTHIER: return (1.0 - e * e) / e;
    case LAW_HU_GUO:   return 3.0 * (1.0 - e) / (2.0 * e);
    default:           return 0.0;
  }
}

// parse and validate every attribute into c; 0 on failure (a warning says why)
static int configure(const mjModel* m, int instance, jbData* c) {
  static const mjtNum kExponent = 1.5, kZero = 0.0, kV0 = 1e-4, kV1 = 1e-3, kMinSpeed = 1e-3;
  if (!read_site(m, instance, "journal_site", &c->journal_site) ||
      !read_site(m, instance, "bearing_site", &c->bearing_site)) {
    return 0;
  }
  c->journal_body = m->site_bodyid[c->journal_site];
  c->bearing_body = m->site_bodyid[c->bearing_site];
  if (c->journal_body == c->bearing_body) {
    mju_warning(JB_NAME " instance %d: journal_site and bearing_site are on the same body",
                instance);
    return 0;
  }
  if (!read_number(m, instance, "clearance", NULL, &c->clearance) ||
      !check(c->clearance > 0, instance, "clearance", c->clearance, "> 0 [m]") ||
      !read_number(m, instance, "journal_radius", NULL, &c->journal_radius) ||
      !check(c->journal_radius > 0, instance, "journal_radius", c->journal_radius, "> 0 [m]") ||
      !read_law(m, instance, &c->law) ||
      !read_number(m, instance, "stiffness", NULL, &c->stiffness) ||
      !check(c->stiffness > 0, instance, "stiffness", c->stiffness, "> 0 [N/m^n]") ||
      !read_number(m, instance, "exponent", &kExponent, &c->exponent) ||
      !check(c->exponent > 0, instance, "exponent", c->exponent, "> 0")) {
    return 0;
  }

  c->restitution = 1.0;
  c->chi = 0.0;
  if (c->law != LAW_HERTZ && c->law != LAW_IMPACT) {
    if (!read_number(m, instance, "restitution", NULL, &c->restitution)) {
      return 0;
    }
    mjtNum e = c->restitution;
    if (c->law == LAW_LN || c->law == LAW_HC) {
      if (!check(e >= 0 && e <= 1, instance, "restitution", e, "in [0, 1]")) return 0;
    } else {
      if (!check(e > 0 && e <= 1, instance, "restitution", e, "in (0, 1]")) return 0;
    }
    c->chi = hysteresis(c->law, e);
  }

  c->c_max = 0.0;
  c->d_max = 1.0;
  if (c->law == LAW_IMPACT) {
    if (!read_number(m, instance, "c_max", NULL, &c->c_max) ||
        !check(c->c_max >= 0, instance, "c_max", c->c_max, ">= 0 [N s/m]") ||
        !read_number(m, instance, "d_max", NULL, &c->d_max) ||
        !check(c->d_max > 0, instance, "d_max", c->d_max, "> 0 [m]")) {
      return 0;
    }
  }

  if (!read_number(m, instance, "friction", &kZero, &c->friction) ||
      !check(c->friction >= 0, instance, "friction", c->friction, ">= 0") ||
      !read_number(m, instance, "v0", &kV0, &c->v0) ||
      !read_number(m, instance, "v1", &kV1, &c->v1) ||
      !check(c->v0 >= 0, instance, "v0", c->v0, ">= 0 [m/s]") ||
      !check(c->v1 > c->v0, instance, "v1", c->v1, "> v0 [m/s]") ||
      !read_number(m, instance, "min_approach_speed", &kMinSpeed, &c->min_speed) ||
      !check(c->min_speed > 0, instance, "min_approach_speed", c->min_speed, "> 0 [m/s]")) {
    return 0;
  }
  return 1;
}


//---------------------------------- contact evaluation --------------------------------------------

static int semi_implicit(const mjModel* m) {
  return m->opt.integrator != mjINT_RK4;
}

// 1 if time t is one step h after time t0 (to rounding: the engine adds h to the time)
static int one_step_after(mjtNum t, mjtNum t0, mjtNum h) {
  return mju_abs(t - (t0 + h)) <= 1e-9 * h;
}

// 1 if a sample recorded at `sample_time` (`have` != 0: recorded at all) is one step old
static int is_last_step(const mjModel* m, const mjData* d, mjtNum have, mjtNum sample_time) {
  return have != 0 && one_step_after(d->time, sample_time, m->opt.timestep);
}

// 1 if such a sample is recent enough to locate an onset (RK4 stages reach 2 steps)
static int is_recent(const mjModel* m, const mjData* d, mjtNum have, mjtNum sample_time) {
  mjtNum age = d->time - sample_time;
  return have != 0 && age > 0 && age <= 2 * m->opt.timestep * (1 + 1e-9);
}

// the backlash stop's sample tests (its state layout: S_HAVE, S_TIME)
static int sample_is_last_step(const mjModel* m, const mjData* d, const mjtNum* s) {
  return is_last_step(m, d, s[S_HAVE], s[S_TIME]);
}

static int sample_is_recent(const mjModel* m, const mjData* d, const mjtNum* s) {
  return is_recent(m, d, s[S_HAVE], s[S_TIME]);
}

// a sampled velocity x advanced by half a step, from the samples x1, x2 one and two steps back
// (the backlash stop's treatment, semi-implicit integrators only: its rate has a constant
// Jacobian, so the whole change of x is the change of the generalized velocities)
static mjtNum half_step_ahead(const mjModel* m, const mjData* d, const mjtNum* s,
                              mjtNum x, mjtNum x1, mjtNum x2) {
  if (!semi_implicit(m) || !sample_is_last_step(m, d, s)) {
    return x;
  }
  mjtNum change = x - x1;  // h times the last step's acceleration
  if (s[S_HAVE] >= 2) {
    change += change - (x1 - x2);  // extrapolated to this step
  }
  return x + 0.5 * change;
}

// normal force of the configured law, the operations of laws.py
static mjtNum normal_force(const jbData* c, mjtNum delta, mjtNum rate, mjtNum vin, mjtNum* fel) {
  *fel = 0;
  if (delta <= 0) {
    return 0;
  }
  *fel = c->stiffness * pow(delta, c->exponent);
  mjtNum f;
  if (c->law == LAW_HERTZ) {
    return *fel;
  } else if (c->law == LAW_IMPACT) {
    mjtNum z = mju_clip(delta / c->d_max, 0.0, 1.0);
    f = *fel + c->c_max * (z * z * (3.0 - 2.0 * z)) * rate;
  } else {
    f = *fel * (1.0 + c->chi * (rate / vin));
  }
  return f > 0 ? f : 0.0;
}

// the law's damping coefficient dF_n/d(delta_dot) [N s/m] at delta > 0 (0: Hertz)
static mjtNum damping_coefficient(const jbData* c, mjtNum delta, mjtNum fel, mjtNum vin) {
  if (c->law == LAW_HERTZ) {
    return 0.0;
  } else if (c->law == LAW_IMPACT) {
    mjtNum z = mju_clip(delta / c->d_max, 0.0, 1.0);
    return c->c_max * (z * z * (3.0 - 2.0 * z));
  }
  return fel * c->chi / vin;
}

// Ambrosio's coefficient c_d(v) sign(v): F_t = -mu F_n ramp(v), the operations of laws._friction
static mjtNum friction_ramp(const jbData* c, mjtNum vt) {
  mjtNum cd = mju_clip((mju_abs(vt) - c->v0) / (c->v1 - c->v0), 0.0, 1.0);
  mjtNum sign = vt > 0 ? 1.0 : (vt < 0 ? -1.0 : 0.0);
  return cd * sign;
}

// Ambrosio friction at v_t, the operations of laws._friction
static mjtNum friction_force(const jbData* c, mjtNum fn, mjtNum vt) {
  if (c->friction == 0) {
    return 0.0;
  }
  return -c->friction * friction_ramp(c, vt) * fn + 0.0;
}

// the tangential velocity v at the step's end that friction evaluated there gives:
// v = v_free + k ramp(v)... with k = -h w_tt mu F_n <= 0, i.e. v + kk ramp(v) = v_free with
// kk = h w_tt mu F_n >= 0; v + kk ramp(v) increases with v, so the root is unique and each
// piece of the ramp is linear (see "Friction near rest")
static mjtNum implicit_sliding_velocity(const jbData* c, mjtNum v_free, mjtNum kk) {
  mjtNum a = mju_abs(v_free), sign = v_free >= 0 ? 1.0 : -1.0;
  if (a <= c->v0 || kk <= 0) {
    return v_free;
  }
  if (a - kk >= c->v1) {
    return sign * (a - kk);  // gross sliding through the step
  }
  mjtNum slope = kk / (c->v1 - c->v0);
  return sign * (a + slope * c->v0) / (1.0 + slope);  // inside the ramp
}

// phi1(-g) = (1 - exp(-g)) / g and psi(g) = (g - 1 + exp(-g)) / g^2 for g >= 0: the mean of
// r(t) over a step h for r' = A - (g / h) r, r(0) = r0, is r0 phi1(-g) + h A psi(g)
static void exponential_means(mjtNum g, mjtNum* phi1, mjtNum* psi) {
  if (g < 1e-3) {  // series: the next terms are g^4 / 120 and g^4 / 720 (< 1e-14 here)
    *phi1 = 1.0 - g / 2.0 + g * g / 6.0 - g * g * g / 24.0;
    *psi = 0.5 - g / 6.0 + g * g / 24.0 - g * g * g / 120.0;
  } else {
    mjtNum em1 = expm1(-g);
    *phi1 = -em1 / g;
    *psi = (g + em1) / (g * g);
  }
}

// the rows of the normal rate and of the tangential velocity over the dofs: with the
// translational and rotational Jacobians of the journal and bearing bodies at their sites,
//   J_n = n' (Jp_J(p_J) - Jp_B(p_B))
//   J_t = t' (Jp_J(p_J) - Jp_B(p_B)) + R_J z' Jr_J - (R_J + c) z' Jr_B
// (the contact points sit at R_J n and (R_J + c) n from the centres, and t' (w x r n) = r z' w);
// scratch: 12 nv
static void contact_rows(const mjModel* m, const mjData* d, const jbData* c, const mjtNum n[3],
                         const mjtNum t[3], const mjtNum z[3], mjtNum* jn, mjtNum* jt,
                         mjtNum* scratch) {
  int nv = m->nv;
  mjtNum *pj = scratch, *rj = scratch + 3 * nv, *pb = scratch + 6 * nv, *rb = scratch + 9 * nv;
  mj_jac(m, d, pj, rj, d->site_xpos + 3 * c->journal_site, c->journal_body);
  mj_jac(m, d, pb, rb, d->site_xpos + 3 * c->bearing_site, c->bearing_body);
  mjtNum arm_j = c->journal_radius, arm_b = c->journal_radius + c->clearance;
  for (int i = 0; i < nv; i++) {
    mjtNum dx = pj[i] - pb[i], dy = pj[nv + i] - pb[nv + i], dzz = pj[2 * nv + i] - pb[2 * nv + i];
    jn[i] = n[0] * dx + n[1] * dy + n[2] * dzz;
    jt[i] = t[0] * dx + t[1] * dy + t[2] * dzz +
            arm_j * (z[0] * rj[i] + z[1] * rj[nv + i] + z[2] * rj[2 * nv + i]) -
            arm_b * (z[0] * rb[i] + z[1] * rb[nv + i] + z[2] * rb[2 * nv + i]);
  }
}

// the equality constraints' rows at most: connect 3, weld 6, joint and tendon couplings 1 (a
// model with other equality kinds, or more rows at run time, keeps the free response)
static int equality_rows_max(const mjModel* m) {
  int n = 0;
  for (int i = 0; i < m->neq; i++) {
    int type = m->eq_type[i];
    if (type == mjEQ_CONNECT) n += 3;
    else if (type == mjEQ_WELD) n += 6;
    else if (type == mjEQ_JOINT || type == mjEQ_TENDON) n += 1;
    else return -1;
  }
  return n;
}

// Turn the free responses M^-1 J_n' and M^-1 J_t' (in c->un, c->ut) into the responses with the
// equality constraints' rows acting as the constraint solver solves them alone (their soft
// dynamics at this state): u -= Y (J_c M^-1 J_c' + R)^-1 J_c u, Y = M^-1 J_c'. A loop closure
// or a pin held by a connect then moves as the loop lets it, not as the free tree would.
static void constrained_responses(const mjModel* m, mjData* d, jbData* c) {
  int nv = m->nv, k = 0;
  if (c->eq_max <= 0) {
    return;
  }
  for (int r = 0; r < d->nefc; r++) {
    if (d->efc_type[r] != mjCNSTR_EQUALITY) continue;
    if (k == c->eq_max) return;  // more rows than the model declares: keep the free response
    mjtNum* row = c->eq_rows + k * nv;
    if (mj_isSparse(m)) {
      mju_zero(row, nv);
      int adr = d->efc_J_rowadr[r];
      for (int j = 0; j < d->efc_J_rownnz[r]; j++) {
        row[d->efc_J_colind[adr + j]] = d->efc_J[adr + j];
      }
    } else {
      mju_copy(row, d->efc_J + r * nv, nv);
    }
    c->eq_z[k] = d->efc_R[r];  // R, held here until the factor is built
    k++;
  }
  if (k == 0) {
    return;
  }
  mj_solveM(m, d, c->eq_y, c->eq_rows, k);
  for (int i = 0; i < k; i++) {
    for (int j = 0; j <= i; j++) {
      mjtNum a = mju_dot(c->eq_rows + i * nv, c->eq_y + j * nv, nv);
      c->eq_a[i * k + j] = a;
      c->eq_a[j * k + i] = a;
    }
    c->eq_a[i * k + i] += c->eq_z[i];
  }
  if (mju_cholFactor(c->eq_a, k, mjMINVAL) < k) {
    return;  // singular: keep the free response
  }
  mjtNum* u[2] = {c->un, c->ut};
  for (int v = 0; v < 2; v++) {
    mjtNum* b = c->eq_z;
    mjtNum* z = c->eq_z + c->eq_max;
    for (int i = 0; i < k; i++) {
      b[i] = mju_dot(c->eq_rows + i * nv, u[v], nv);
    }
    mju_cholSolve(z, c->eq_a, b, k);
    for (int i = 0; i < k; i++) {
      mju_addToScl(u[v], c->eq_y + i * nv, -z[i], nv);
    }
  }
}

// evaluate the contact at the current kinematics of d; pure in (d, state). For the
// semi-implicit integrators it also fills the slot's vectors (jbData.vec, see store).
static void evaluate(const mjModel* m, mjData* d, jbData* c, const mjtNum* s, jbEval* ev) {
  const mjtNum* pj = d->site_xpos + 3 * c->journal_site;
  const mjtNum* pb = d->site_xpos + 3 * c->bearing_site;
  const mjtNum* mat = d->site_xmat + 9 * c->bearing_site;
  mjtNum z[3] = {mat[2], mat[5], mat[8]};
  mjtNum h = m->opt.timestep;
  int nv = m->nv;

  // eccentricity in the bearing plane
  mjtNum dist[3], e[3];
  mju_sub3(dist, pj, pb);
  mjtNum dz = mju_dot3(dist, z);
  mju_addScl3(e, dist, z, -dz);
  mjtNum ecc = mju_norm3(e);
  mjtNum* n = ev->normal;
  if (ecc > mjMINVAL) {
    mju_scl3(n, e, 1.0 / ecc);
  } else {
    n[0] = mat[0];
    n[1] = mat[3];
    n[2] = mat[6];
  }
  mju_cross(ev->tangent, z, n);

  // site velocities: [rotation; translation] in world orientation
  mjtNum vj[6], vb[6];
  mj_objectVelocity(m, d, mjOBJ_SITE, c->journal_site, vj, 0);
  mj_objectVelocity(m, d, mjOBJ_SITE, c->bearing_site, vb, 0);

  // d|e|/dt
  mjtNum vrel[3];
  mju_sub3(vrel, vj + 3, vb + 3);
  mjtNum rate_geo = mju_dot3(n, vrel);
  if (ecc > mjMINVAL && dz != 0) {
    mjtNum zdot[3];
    mju_cross(zdot, vb, z);
    rate_geo -= dz * mju_dot3(dist, zdot) / ecc;
  }

  // contact points and the tangential velocity between them
  mjtNum rj[3], rb[3], wj[3], wb[3];
  mju_scl3(rj, n, c->journal_radius);
  mju_scl3(rb, n, c->journal_radius + c->clearance);
  mju_add3(ev->pj, pj, rj);
  mju_add3(ev->pb, pb, rb);
  mju_cross(wj, vj, rj);
  mju_cross(wb, vb, rb);
  mjtNum vpj[3], vpb[3], vp[3];
  mju_add3(vpj, vj + 3, wj);
  mju_add3(vpb, vb + 3, wb);
  mju_sub3(vp, vpj, vpb);
  mjtNum vt_geo = mju_dot3(ev->tangent, vp);
  mjtNum delta = ecc - c->clearance;

  // In-step treatment (semi-implicit integrators): the rows of the normal rate and of the
  // tangential velocity over the dofs, the joint's own inverse inertias along them, and the
  // last step's velocity change from every other force (state), projected on the rows.
  int instep = semi_implicit(m);
  int last = is_last_step(m, d, s[B_HAVE], s[B_TIME]);
  mjtNum w_nn = 0, w_nt = 0, w_tt = 0, other_n = 0, other_t = 0;
  mjtNum* jn = c->vec_n;
  mjtNum* jt = c->vec_t;
  if (instep) {
    contact_rows(m, d, c, n, ev->tangent, z, jn, jt, c->scratch);
    mj_solveM(m, d, c->un, jn, 2);  // un, ut: the two rows stored one after the other
    constrained_responses(m, d, c);
    w_nn = mju_dot(jn, c->un, nv);
    w_nt = mju_dot(jn, c->ut, nv);
    w_tt = mju_dot(jt, c->ut, nv);
    if (last) {
      other_n = mju_dot(jn, s + B_OTHER, nv);
      other_t = mju_dot(jt, s + B_OTHER, nv);
    }
  }

  // the rate at the step's time with no force of this joint: the sampled rate (half a step
  // behind for the semi-implicit integrators) plus half the other forces' velocity change
  mjtNum rate_free = rate_geo + 0.5 * other_n;

  // approach speed: kept during an impact, located at the crossing at onset
  mjtNum vin = 0;
  if (delta > 0) {
    if (s[B_CONTACT] != 0) {
      vin = s[B_VIN];
    } else if (s[B_DELTA] <= 0 && (instep ? last : is_recent(m, d, s[B_HAVE], s[B_TIME]))) {
      mjtNum theta = s[B_DELTA] / (s[B_DELTA] - delta);
      vin = s[B_RATE] + theta * (rate_free - s[B_RATE]);
    } else {
      vin = rate_free;
    }
    vin = vin > c->min_speed ? vin : c->min_speed;
  }

  // the rate entering the law: the mean over the step of the normal rate's velocity part,
  // with this joint's damping integrated exponentially and its elastic force held
  mjtNum rate = rate_geo, fel = 0;
  if (delta > 0) {
    fel = c->stiffness * pow(delta, c->exponent);
  }
  if (instep) {
    mjtNum ft_last = last ? s[B_FT] : 0.0;
    mjtNum g = delta > 0 ? h * w_nn * damping_coefficient(c, delta, fel, vin) : 0.0;
    mjtNum phi1, psi;
    exponential_means(g, &phi1, &psi);
    rate = rate_geo * phi1 + (other_n - h * w_nn * fel + h * w_nt * ft_last) * psi;
  }
  mjtNum fn = normal_force(c, delta, rate, vin, &fel);

  // friction at the tangential velocity it leaves at the step's end (semi-implicit), or at
  // the sampled one (RK4)
  mjtNum vt = vt_geo, ft = 0;
  if (c->friction != 0 && fn > 0) {
    if (instep) {
      mjtNum v_free = vt_geo + other_t - h * w_nt * fn;
      mjtNum v_end = implicit_sliding_velocity(c, v_free, h * w_tt * c->friction * fn);
      ft = friction_force(c, fn, v_end);
      vt = 0.5 * (vt_geo + v_end);
    } else {
      ft = friction_force(c, fn, vt_geo);
    }
  }

  if (instep) {  // this joint's own velocity change over the step, h M^-1 J' f
    for (int i = 0; i < nv; i++) {
      c->own[i] = h * (ft * c->ut[i] - fn * c->un[i]);
    }
  }

  ev->time = d->time;
  ev->valid = 1;
  ev->delta = delta;
  ev->rate_geo = rate_geo;
  ev->rate = rate;
  ev->vt_geo = vt_geo;
  ev->vin = vin;
  ev->fn = fn;
  ev->ft = ft;
  ev->fel = fel;
  ev->ecc = ecc;
  ev->power = delta > 0 ? (fn - fel) * rate - ft * vt : 0.0;
}

// add the contact force to qfrc_passive: f on the journal at P_J, -f on the bearing at P_B
static void apply(const mjModel* m, mjData* d, const jbData* c, const jbEval* ev) {
  if (ev->fn == 0 && ev->ft == 0) {
    return;
  }
  mjtNum f[3], g[3];
  mju_scl3(f, ev->normal, -ev->fn);
  mju_addToScl3(f, ev->tangent, ev->ft);
  mju_scl3(g, f, -1.0);
  if (c->journal_body) {
    mj_applyFT(m, d, f, NULL, ev->pj, c->journal_body, d->qfrc_passive);
  }
  if (c->bearing_body) {
    mj_applyFT(m, d, g, NULL, ev->pb, c->bearing_body, d->qfrc_passive);
  }
}

// The per-mjData evaluation caches of the passive plugins hold structs that begin with
// (mjtNum time; int valid;). cache_slot picks where an evaluation at `time` goes: the slot
// already holding that time, else a free one, else the next in round-robin order.
typedef struct {
  mjtNum time;
  int valid;
} evalHead;

static int cache_slot(const void* cache, size_t stride, int n, mjtNum time, int* next) {
  const char* base = (const char*)cache;
  for (int i = 0; i < n; i++) {
    const evalHead* e = (const evalHead*)(base + i * stride);
    if (e->valid && e->time == time) return i;
  }
  for (int i = 0; i < n; i++) {
    if (!((const evalHead*)(base + i * stride))->valid) return i;
  }
  int slot = *next;
  *next = (*next + 1) % n;
  return slot;
}

// the cached evaluation made one step h before `time` (the step's start), or NULL
static const void* cache_step_start(const void* cache, size_t stride, int n, mjtNum time,
                                    mjtNum h) {
  const char* base = (const char*)cache;
  for (int i = 0; i < n; i++) {
    const evalHead* e = (const evalHead*)(base + i * stride);
    if (e->valid && one_step_after(time, e->time, h)) return e;
  }
  return NULL;
}

// keep an evaluation made at d's state (with the vectors the in-step treatment left in c)
static void store(const mjModel* m, const mjData* d, jbData* c, const jbEval* ev) {
  int slot = cache_slot(c->cache, sizeof(jbEval), JB_NCACHE, ev->time, &c->cache_next);
  c->cache[slot] = *ev;
  if (semi_implicit(m)) {
    int nv = m->nv;
    mjtNum* v = c->slot_vec + 3 * nv * slot;
    mju_copy(v, d->qvel, nv);
    mju_copy(v + nv, c->own, nv);
    mju_copy(v + 2 * nv, c->vec_n, nv);
  }
}

// the cache slot holding the evaluation made one step before `time`, or -1
static int step_start_slot(const jbData* c, mjtNum time, mjtNum h) {
  const jbEval* ev = (const jbEval*)cache_step_start(c->cache, sizeof(jbEval), JB_NCACHE, time, h);
  return ev ? (int)(ev - c->cache) : -1;
}

static void clear_cache(jbData* c) {
  for (int i = 0; i < JB_NCACHE; i++) {
    c->cache[i].valid = 0;
  }
  c->cache_next = 0;
}


//---------------------------------- plugin callbacks ----------------------------------------------

// the cache slot evaluated at d's time, velocities and eccentricity (semi-implicit integrators,
// where an evaluation costs Jacobians and solves), or -1: a sensor reads it instead of
// evaluating the same state again
static int same_state_slot(const mjModel* m, const mjData* d, const jbData* c) {
  if (!semi_implicit(m)) {
    return -1;
  }
  int nv = m->nv;
  mjtNum dist[3], e[3];
  const mjtNum* mat = d->site_xmat + 9 * c->bearing_site;
  mjtNum z[3] = {mat[2], mat[5], mat[8]};
  mju_sub3(dist, d->site_xpos + 3 * c->journal_site, d->site_xpos + 3 * c->bearing_site);
  mju_addScl3(e, dist, z, -mju_dot3(dist, z));
  mjtNum ecc = mju_norm3(e);
  for (int i = 0; i < JB_NCACHE; i++) {
    const jbEval* ev = c->cache + i;
    if (ev->valid && ev->time == d->time && ev->ecc == ecc &&
        !memcmp(c->slot_vec + 3 * nv * i, d->qvel, sizeof(mjtNum) * nv)) {
      return i;
    }
  }
  return -1;
}

static int jb_nstate(const mjModel* m, int instance) {
  return B_OTHER + m->nv;
}

// the sensordata addresses of a plugin instance's sensors: a malloc'd array (at least one
// element, so that NULL means out of memory) and their count in *n
static int* instance_sensors(const mjModel* m, int instance, int* n) {
  *n = 0;
  for (int i = 0; i < m->nsensor; i++) {
    if (m->sensor_type[i] == mjSENS_PLUGIN && m->sensor_plugin[i] == instance) {
      (*n)++;
    }
  }
  int* adr = (int*)malloc(sizeof(int) * (*n > 0 ? *n : 1));
  if (!adr) {
    return NULL;
  }
  int k = 0;
  for (int i = 0; i < m->nsensor; i++) {
    if (m->sensor_type[i] == mjSENS_PLUGIN && m->sensor_plugin[i] == instance) {
      adr[k++] = m->sensor_adr[i];
    }
  }
  return adr;
}

static int jb_nsensordata(const mjModel* m, int instance, int sensor_id) {
  return JB_NSENSOR;
}

static void jb_free(jbData* c) {
  free(c->sensor_adr);
  free(c->vec_n);
  free(c->eq_rows);
  free(c);
}

static int jb_init(const mjModel* m, mjData* d, int instance) {
  jbData* c = (jbData*)calloc(1, sizeof(jbData));
  if (!c) {
    mju_warning(JB_NAME " instance %d: out of memory", instance);
    return -1;
  }
  if (!configure(m, instance, c)) {
    free(c);
    return -1;
  }
  c->sensor_adr = instance_sensors(m, instance, &c->nsensor);
  int nv = m->nv > 0 ? m->nv : 1;
  c->vec_n = (mjtNum*)calloc((size_t)(17 + 3 * JB_NCACHE) * nv, sizeof(mjtNum));
  if (!c->sensor_adr || !c->vec_n) {
    jb_free(c);
    mju_warning(JB_NAME " instance %d: out of memory", instance);
    return -1;
  }
  c->vec_t = c->vec_n + nv;
  c->un = c->vec_n + 2 * nv;
  c->ut = c->vec_n + 3 * nv;
  c->own = c->vec_n + 4 * nv;
  c->scratch = c->vec_n + 5 * nv;
  c->slot_vec = c->vec_n + 17 * nv;
  c->eq_max = equality_rows_max(m);
  if (c->eq_max > 0) {
    int k = c->eq_max;
    c->eq_rows = (mjtNum*)calloc((size_t)(2 * k * nv + k * k + 2 * k), sizeof(mjtNum));
    if (!c->eq_rows) {
      jb_free(c);
      mju_warning(JB_NAME " instance %d: out of memory", instance);
      return -1;
    }
    c->eq_y = c->eq_rows + k * nv;
    c->eq_a = c->eq_y + k * nv;
    c->eq_z = c->eq_a + k * k;
  }
  d->plugin_data[instance] = (uintptr_t)c;
  return 0;
}

static void jb_destroy(mjData* d, int instance) {
  jbData* c = (jbData*)d->plugin_data[instance];
  if (c) {
    jb_free(c);
  }
  d->plugin_data[instance] = 0;
}

static void jb_copy(mjData* dest, const mjModel* m, const mjData* src, int instance) {
  jbData* to = (jbData*)dest->plugin_data[instance];
  const jbData* from = (const jbData*)src->plugin_data[instance];
  if (to && from) {
    memcpy(to->cache, from->cache, sizeof(to->cache));
    to->cache_next = from->cache_next;
    mju_copy(to->slot_vec, from->slot_vec, 3 * JB_NCACHE * m->nv);
  }
}

static void jb_reset(const mjModel* m, mjtNum* plugin_state, void* plugin_data, int instance) {
  mju_zero(plugin_state, B_OTHER + m->nv);
  if (plugin_data) {
    clear_cache((jbData*)plugin_data);
  }
}

static void jb_compute(const mjModel* m, mjData* d, int instance, int capability_bit) {
  jbData* c = (jbData*)d->plugin_data[instance];
  const mjtNum* s = d->plugin_state + m->plugin_stateadr[instance];
  jbEval ev;
  int slot = (capability_bit & mjPLUGIN_PASSIVE) ? -1 : same_state_slot(m, d, c);
  if (slot >= 0) {
    ev = c->cache[slot];  // the sensor stage after the passive stage of one forward pass
  } else {
    evaluate(m, d, c, s, &ev);
  }

  if (capability_bit & mjPLUGIN_PASSIVE) {
    store(m, d, c, &ev);
    apply(m, d, c, &ev);
  }

  if (capability_bit & mjPLUGIN_SENSOR) {
    mjtNum out[JB_NSENSOR] = {
      ev.fn, ev.ft, ev.delta, ev.rate, ev.vin,
      ev.delta > 0 ? ev.fel * ev.delta / (c->exponent + 1) : 0.0,
      s[B_WORK], ev.ecc
    };
    for (int i = 0; i < c->nsensor; i++) {
      mju_copy(d->sensordata + c->sensor_adr[i], out, JB_NSENSOR);
    }
  }
}

// once per step, after integration: commit the evaluation made at the step's start state
static void jb_advance(const mjModel* m, mjData* d, int instance) {
  jbData* c = (jbData*)d->plugin_data[instance];
  mjtNum* s = d->plugin_state + m->plugin_stateadr[instance];
  mjtNum h = m->opt.timestep;
  int slot = step_start_slot(c, d->time, h);
  if (slot >= 0) {  // none when passive forces are disabled: no force was applied, nothing to record
    const jbEval* ev = c->cache + slot;
    s[B_WORK] += h * ev->power;
    s[B_CONTACT] = ev->delta > 0 ? 1.0 : 0.0;
    s[B_VIN] = ev->delta > 0 ? ev->vin : 0.0;
    s[B_TIME] = ev->time;
    s[B_DELTA] = ev->delta;
    s[B_FT] = ev->ft;
    s[B_RATE] = ev->rate_geo;
    if (semi_implicit(m)) {
      // the step's velocity change: what this joint's force did, the rest (other forces),
      // and the rate at the evaluation's time (the mean of the step's start and end rates)
      int nv = m->nv;
      const mjtNum* v = c->slot_vec + 3 * nv * slot;
      mjtNum half = 0;
      for (int i = 0; i < nv; i++) {
        mjtNum dv = d->qvel[i] - v[i];
        s[B_OTHER + i] = dv - v[nv + i];
        half += v[2 * nv + i] * dv;
      }
      s[B_RATE] += 0.5 * half;
    }
    s[B_HAVE] = 1.0;
    s[B_NSTEP] += 1.0;
  }
  clear_cache(c);
}


//==================================================================================================
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
  c->sensor_adr = instance_sensors(m, instance, &c->nsensor);
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
  if (!c->valid || !one_step_after(d->time, c->time, h)) {
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


//==================================================================================================
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
  bsEval cache[JB_NCACHE];
  int cache_next;
} bsData;

static int read_hinge(const mjModel* m, int instance, const char* name, int* qpos, int* dof) {
  const char* text = attr(m, instance, name);
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
  if (!read_number(m, instance, "half_width", NULL, &c->half_width) ||
      !check(c->half_width > 0, instance, "half_width", c->half_width, "> 0 [rad]") ||
      !read_number(m, instance, "stiffness", NULL, &c->stiffness) ||
      !check(c->stiffness > 0, instance, "stiffness", c->stiffness, "> 0 [N m/rad^n]") ||
      !read_number(m, instance, "exponent", &kOne, &c->exponent) ||
      !check(c->exponent > 0, instance, "exponent", c->exponent, "> 0") ||
      !read_number(m, instance, "restitution", NULL, &c->restitution) ||
      !check(c->restitution >= 0 && c->restitution <= 1, instance, "restitution",
             c->restitution, "in [0, 1]") ||
      !read_number(m, instance, "min_approach_speed", &kMinSpeed, &c->min_speed) ||
      !check(c->min_speed > 0, instance, "min_approach_speed", c->min_speed, "> 0 [rad/s]")) {
    return 0;
  }
  c->chi = hysteresis(LAW_LN, c->restitution);
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
      mjtNum w = (semi_implicit(m) && sample_is_last_step(m, d, s)) ? theta + 0.5 : theta;
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
  c->sensor_adr = instance_sensors(m, instance, &c->nsensor);
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
  for (int i = 0; i < JB_NCACHE; i++) {
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
    c->cache[cache_slot(c->cache, sizeof(bsEval), JB_NCACHE, ev.time, &c->cache_next)] = ev;
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
  const bsEval* ev = (const bsEval*)cache_step_start(c->cache, sizeof(bsEval), JB_NCACHE,
                                                      d->time, h);
  if (ev) {
    int consecutive = s[S_HAVE] != 0 && one_step_after(ev->time, s[S_TIME], h) &&
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

mjPLUGIN_LIB_INIT(clearance_journal_bearing) {
  mjpPlugin plugin;
  mjp_defaultPlugin(&plugin);
  plugin.name = JB_NAME;
  plugin.capabilityflags |= mjPLUGIN_PASSIVE | mjPLUGIN_SENSOR;
  plugin.needstage = mjSTAGE_VEL;
  plugin.nattribute = sizeof(kAttributes) / sizeof(kAttributes[0]);
  plugin.attributes = kAttributes;
  plugin.nstate = jb_nstate;
  plugin.nsensordata = jb_nsensordata;
  plugin.init = jb_init;
  plugin.destroy = jb_destroy;
  plugin.copy = jb_copy;
  plugin.reset = jb_reset;
  plugin.compute = jb_compute;
  plugin.advance = jb_advance;
  mjp_registerPlugin(&plugin);

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
