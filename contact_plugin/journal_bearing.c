// clearance.journal_bearing: exact journal-bearing contact of a revolute clearance joint.
// (The same library registers clearance.work, the energy meter's work sensor, work_meter.c, and
// clearance.backlash_stop, the gear mesh's impact law at the ends of a backlash band,
// backlash_stop.c; registration in clearance_contact.c.)
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
// Kinematic forcing. The sampled rate also changes, at constant generalized velocities, with the
// geometry (the turning normal, the Jacobians' own rates: h J_dot v, the crank's centripetal
// acceleration on a slider-crank). Over the step's velocity interval [t - h/2, t + h/2] that
// change is a forcing of the rate ODE, and the rate at the interval's start is r0 - kin/2
// (r0 itself is at t in its kinematic part): so the ODE of "Normal force" starts from
// r0 - kin/2 and A gains kin/h. With small g the two cancel in the mean (the velocity part alone
// is advanced, as above); with a large g (the oil film, a grazing dry contact) the rate then
// settles on the lag the forcing needs instead of on h times it. kin is measured from the last
// step: this step's sampled rate, less the last step's, less the last step's whole velocity
// change along the row; at a step with no history, from the Jacobians' time derivatives
// (mj_jacDot) at the state, the turning normal's share left out.
//
// Oil film. A lubricated joint (attribute film: short | long) adds the film force of
// contact_calibration/film.py (film_scalar, operation by operation): with e seen from the
// bearing, its rate v = (v_n, v_f) along (n, t) (v_f = t.(v_J - v_B) - |e| w_B) and the spin
// w = w_J - w_B about z, F = F_0 - D v, F_0 = S w (-a_r n + a_t t), D = (S/c) [[b_r, -b_t],
// [-b_t, g_t]] at eps = min(|e|/c, 1 - h_t/c) (the transition: below the film thickness h_t the
// coefficients are held; the dry law acts on delta > 0 as without oil). F acts through the
// journal's centre and -F through the bearing's, with the shear torques
// T_J = -T_c - |e| F_t / 2 and T_B = T_c - |e| F_t / 2, T_c = 2 pi mu R^3 L w / (c sqrt(1 - eps^2)).
// The film's damping is stiff (h w D reaches 1e3 near the transition at µs steps), so for the
// semi-implicit integrators the normal rate and v_f are integrated together, the 2x2 form of
// "Normal force": r = (r_n, r_f), r' = A - (1/h) G r, G = h W K, W the joint's own response on
// the two rows, K = D + diag(C, 0) (C the dry law's damping), A the held forces' (F_0, -F_el,
// the Couette torques', the last friction) plus the other forces' and the kinematic forcing;
// the rates entering the forces are the exact means phi1(-G) r0 + h psi(G) A, computed through
// the symmetric h L'W L (K = L L') whose eigenvalues are G's. The torques' own response and
// the film's moment share are held over the step. RK4 evaluates the film at the state's rates.
//
// State (nstate = 11 + 2 nv mjtNums per instance, part of mjSTATE_PLUGIN, so it travels with
// mj_getState/mj_setState and through mujoco.rollout chunks):
//   [0] time of the last recorded sample [s]    [1] delta there [m]
//   [2] normal rate at that sample's time [m/s] [3] friction force F_t applied there [N]
//   [4] 1 once a sample is recorded, else 0     [5] 1 while in an impact, else 0
//   [6] approach speed of that impact [m/s]     [7] dissipated work so far [J]
//   [8] number of recorded steps                [9] sampled normal rate there [m/s]
//   [10] sampled film rate v_f there [m/s]      [11 .. 11 + nv) the last step's velocity change
//                                                    from the other forces [m/s, rad/s]
//   [11 + nv .. 11 + 2 nv) the last step's whole velocity change
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
// Sensor output (nsensordata = 10), evaluated at the current state:
//   [0] F_n normal force [N] (>= 0)   [1] F_t tangential force on the journal along t [N]
//   [2] delta penetration [m]         [3] delta_dot entering the law [m/s] (> 0 approaching)
//   [4] v_in approach speed [m/s] (0 out of contact)
//   [5] contact potential energy K delta^(n+1) / (n+1) [J] (0 for delta <= 0)
//   [6] work dissipated by the contact so far [J] (normal damping + friction; recorded once per
//       step in `advance` as timestep * power of the applied force: (F_n - F_el) rate - F_t v_t,
//       v_t the mean of the step's start and end tangential velocities)
//   [7] |e| eccentricity magnitude [m]
//   [8] film force on the journal along n [N] (negative: towards the centre; 0 without oil)
//   [9] film force on the journal along t [N]
// (with a film, [6] also holds the film's dissipation: minus its power on the two bodies)
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
//   film: none (default) | short | long; with a film: viscosity mu [Pa s] > 0,
//        bearing_length L [m] > 0, transition_thickness h_t [m] in (0, c)

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <mujoco/mjplugin.h>
#include <mujoco/mujoco.h>

#include "contact_laws.h"
#include "film.h"
#include "instep.h"
#include "plugin_util.h"

#define JB_NAME "clearance.journal_bearing"
#define JB_NSENSOR 10

// state layout of a journal bearing (B_OTHER and B_DV: nv values each, B_DV = B_OTHER + nv)
enum {
  B_TIME = 0, B_DELTA, B_RATE, B_FT, B_HAVE, B_CONTACT, B_VIN, B_WORK, B_NSTEP, B_RATE0,
  B_RATEF0, B_OTHER
};


static const char* const kAttributes[] = {
  "journal_site", "bearing_site", "clearance", "journal_radius", "law", "stiffness",
  "exponent", "restitution", "c_max", "d_max", "friction", "v0", "v1", "min_approach_speed",
  "film", "viscosity", "bearing_length", "transition_thickness", "compliance", "reference_force",
  "offset", "max_penetration"
};

// one force evaluation
typedef struct {
  mjtNum time;       // d->time of the evaluation
  int valid;         // 1 if this cache slot holds an evaluation
  mjtNum delta;      // penetration [m]
  mjtNum rate_geo;   // geometric penetration rate [m/s]
  mjtNum rate;       // rate entering the law [m/s]
  mjtNum vt_geo;     // geometric tangential velocity [m/s]
  mjtNum vtf_geo;    // film: e's sampled tangential rate seen from the bearing [m/s]
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
  mjtNum film_n;     // film force on the journal along n [N] (negative: pushes it back)
  mjtNum film_t;     // film force on the journal along t [N]
  mjtNum torque_j;   // film shear torque on the journal about z [N m]
  mjtNum torque_b;   // film shear torque on the bearing about z [N m]
  mjtNum axis[3];    // z, the joint's axis (world)
} jbEval;

// parsed configuration and per-mjData scratch, in d->plugin_data[instance]
typedef struct {
  int journal_site, bearing_site;
  int journal_body, bearing_body;
  mjtNum clearance, journal_radius;
  clLaw lw;                  // the normal law
  clFilm film;               // the oil film (film.model FILM_NONE: a dry joint)
  clFriction fr;             // Ambrosio's friction
  mjtNum min_speed;
  int nsensor;
  int* sensor_adr;           // sensordata addresses of this instance's sensors
  jbEval cache[CL_NCACHE];   // passive evaluations since the last advance
  int cache_next;            // round-robin slot
  // in-step treatment (semi-implicit integrators), one block of 22 + 3 CL_NCACHE times nv values
  // allocated in init (vec_t follows vec_n, ut follows un: each pair is solved in one call):
  mjtNum* vec_n;             // row of the normal rate over the dofs (nv)
  mjtNum* vec_t;             // row of the tangential velocity (nv)
  mjtNum* un;                // M^-1 vec_n' (nv)
  mjtNum* ut;                // M^-1 vec_t' (nv)
  mjtNum* own;               // this joint's velocity change over the step, h M^-1 J' f (nv)
  mjtNum* scratch;           // two bodies' Jacobians (12 nv)
  mjtNum* vec_tf;            // film: row of the tangential rate of e seen from the bearing (nv)
  mjtNum* u_tf;              // film: M^-1 vec_tf' (nv)
  mjtNum* vec_rj;            // film: row of the journal's angular velocity about z (nv)
  mjtNum* vec_rb;            // film: row of the bearing's angular velocity about z (nv)
  mjtNum* own_film;          // film: its generalized force, then h M^-1 of it (nv)
  mjtNum* slot_vec;          // per cache slot: qvel, own and vec_n at the evaluation (3 nv each)
  clEquality eq;             // the equality constraints' response (instep.h)
} jbData;


//---------------------------------- attribute parsing ---------------------------------------------


// parse and validate every attribute into c; 0 on failure (a warning says why)
static int configure(const mjModel* m, int instance, jbData* c) {
  static const mjtNum kMinSpeed = 1e-3;
  if (!cl_read_site(m, instance, "journal_site", &c->journal_site) ||
      !cl_read_site(m, instance, "bearing_site", &c->bearing_site)) {
    return 0;
  }
  c->journal_body = m->site_bodyid[c->journal_site];
  c->bearing_body = m->site_bodyid[c->bearing_site];
  if (c->journal_body == c->bearing_body) {
    mju_warning(JB_NAME " instance %d: journal_site and bearing_site are on the same body",
                instance);
    return 0;
  }
  if (!cl_read_number(m, instance, "clearance", NULL, &c->clearance) ||
      !cl_check(m, c->clearance > 0, instance, "clearance", c->clearance, "> 0 [m]") ||
      !cl_read_number(m, instance, "journal_radius", NULL, &c->journal_radius) ||
      !cl_check(m, c->journal_radius > 0, instance, "journal_radius", c->journal_radius, "> 0 [m]") ||
      !cl_configure_law(m, instance, &c->lw) ||
      !cl_configure_film(m, instance, c->clearance, c->journal_radius, &c->film)) {
    return 0;
  }

  if (!cl_configure_friction(m, instance, &c->fr) ||
      !cl_read_number(m, instance, "min_approach_speed", &kMinSpeed, &c->min_speed) ||
      !cl_check(m, c->min_speed > 0, instance, "min_approach_speed", c->min_speed, "> 0 [m/s]")) {
    return 0;
  }
  return 1;
}


//---------------------------------- contact evaluation --------------------------------------------


// the rows of the normal rate and of the tangential velocity over the dofs: with the
// translational and rotational Jacobians of the journal and bearing bodies at their sites,
//   J_n = n' (Jp_J(p_J) - Jp_B(p_B))
//   J_t = t' (Jp_J(p_J) - Jp_B(p_B)) + R_J z' Jr_J - (R_J + c) z' Jr_B
// (the contact points sit at R_J n and (R_J + c) n from the centres, and t' (w x r n) = r z' w);
// with a film also its rows (vec_tf, vec_rj, vec_rb: see "Oil film"); scratch: 12 nv
static void contact_rows(const mjModel* m, const mjData* d, jbData* c, const mjtNum n[3],
                         const mjtNum t[3], const mjtNum z[3], mjtNum ecc, mjtNum* jn, mjtNum* jt,
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
  if (c->film.model != FILM_NONE) {  // the film's rows: e's tangential rate seen from the
    for (int i = 0; i < nv; i++) {   // bearing, t'(v_J - v_B) - |e| w_B, and the two spins
      mjtNum dx = pj[i] - pb[i], dy = pj[nv + i] - pb[nv + i], dzz = pj[2 * nv + i] - pb[2 * nv + i];
      c->vec_rj[i] = z[0] * rj[i] + z[1] * rj[nv + i] + z[2] * rj[2 * nv + i];
      c->vec_rb[i] = z[0] * rb[i] + z[1] * rb[nv + i] + z[2] * rb[2 * nv + i];
      c->vec_tf[i] = t[0] * dx + t[1] * dy + t[2] * dzz - ecc * c->vec_rb[i];
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
  int instep = cl_semi_implicit(m);
  int last = cl_is_last_step(m, d, s[B_HAVE], s[B_TIME]);
  int film = c->film.model != FILM_NONE;
  mjtNum w_nn = 0, w_nt = 0, w_tt = 0, other_n = 0, other_t = 0;
  mjtNum w_nf = 0, w_ff = 0, w_tf = 0, other_f = 0;  // the film's tangential row (f)
  mjtNum* jn = c->vec_n;
  mjtNum* jt = c->vec_t;
  int neq = 0;
  if (instep) {
    contact_rows(m, d, c, n, ev->tangent, z, ecc, jn, jt, c->scratch);
    mj_solveM(m, d, c->un, jn, 2);  // un, ut: the two rows stored one after the other
    neq = cl_equality_factor(m, d, &c->eq);
    if (neq) {
      cl_constrain(&c->eq, neq, nv, c->un);
      cl_constrain(&c->eq, neq, nv, c->ut);
    }
    w_nn = mju_dot(jn, c->un, nv);
    w_nt = mju_dot(jn, c->ut, nv);
    w_tt = mju_dot(jt, c->ut, nv);
    if (film) {
      mj_solveM(m, d, c->u_tf, c->vec_tf, 1);
      if (neq) cl_constrain(&c->eq, neq, nv, c->u_tf);
      w_nf = mju_dot(jn, c->u_tf, nv);
      w_ff = mju_dot(c->vec_tf, c->u_tf, nv);
      w_tf = mju_dot(jt, c->u_tf, nv);
    }
    if (last) {
      other_n = mju_dot(jn, s + B_OTHER, nv);
      other_t = mju_dot(jt, s + B_OTHER, nv);
      if (film) other_f = mju_dot(c->vec_tf, s + B_OTHER, nv);
    }
  }

  // the sampled rate's change over the last step from the geometry alone (the turning normal and
  // Jacobian at the last step's velocities: h J_dot v): this step's sampled rate, less the last
  // step's, less the last step's whole velocity change along the row ("Kinematic forcing")
  mjtNum kin_n = instep && last ? rate_geo - s[B_RATE0] - mju_dot(jn, s + B_OTHER + nv, nv) : 0.0;
  mjtNum kin_f_start = 0;  // the film row's, at a step with no history (below)
  if (instep && !last) {
    // no history (a run's first step, a state set by hand): the Jacobians' own rates at the
    // state, h n'(Jdot_J - Jdot_B) v (the turning normal's share, |e_dot_t|^2/|e|, left out)
    mjtNum *dj = c->scratch, *djr = c->scratch + 3 * nv, *db = c->scratch + 6 * nv,
           *dbr = c->scratch + 9 * nv;
    mj_jacDot(m, d, dj, djr, pj, c->journal_body);
    mj_jacDot(m, d, db, dbr, pb, c->bearing_body);
    mjtNum an3[3] = {0, 0, 0}, ab3[3] = {0, 0, 0}, wb = 0;
    for (int k = 0; k < 3; k++) {
      an3[k] = mju_dot(dj + k * nv, d->qvel, nv) - mju_dot(db + k * nv, d->qvel, nv);
      ab3[k] = mju_dot(dbr + k * nv, d->qvel, nv);
    }
    wb = mju_dot3(ab3, z);
    kin_n = h * mju_dot3(n, an3);
    kin_f_start = h * (mju_dot3(ev->tangent, an3) - ecc * wb);
  }

  // the rate at the step's time with no force of this joint: the sampled rate (half a step
  // behind for the semi-implicit integrators) plus half the other forces' velocity change
  mjtNum rate_free = rate_geo + 0.5 * other_n;

  // approach speed: kept during an impact, located at the crossing at onset
  mjtNum vin = 0;
  if (delta > 0) {
    if (s[B_CONTACT] != 0) {
      vin = s[B_VIN];
    } else if (s[B_DELTA] <= 0 && (instep ? last : cl_is_recent(m, d, s[B_HAVE], s[B_TIME]))) {
      mjtNum theta = s[B_DELTA] / (s[B_DELTA] - delta);
      vin = s[B_RATE] + theta * (rate_free - s[B_RATE]);
    } else {
      vin = rate_free;
    }
    vin = vin > c->min_speed ? vin : c->min_speed;
  }

  // the film's coefficients at the clamped eccentricity ratio, its held part F_0 and damping D
  // (in the directions n and t), and its rates at the state: e's rate seen from the bearing
  // (the normal one is rate_geo) and the spin of the journal relative to the bearing
  mjtNum kf[5] = {0, 0, 0, 0, 0}, f0n = 0, f0t = 0, dnn = 0, dnt = 0, dtt = 0;
  mjtNum vtf_geo = 0, spin = 0, ratio = 0, kin_f = 0;
  if (film) {
    spin = mju_dot3(vj, z) - mju_dot3(vb, z);  // the sites' angular velocities
    vtf_geo = mju_dot3(ev->tangent, vrel) - ecc * mju_dot3(vb, z);
    if (instep) {
      kin_f = last ? vtf_geo - s[B_RATEF0] - mju_dot(c->vec_tf, s + B_OTHER + nv, nv) : kin_f_start;
    }
    ratio = mju_min(ecc / c->film.clearance, c->film.ratio_max);
    cl_film_terms(c->film.model, ratio, kf);
    mjtNum sc = c->film.scale, g = c->film.scale / c->film.clearance;
    f0n = -sc * kf[0] * spin;
    f0t = sc * kf[2] * spin;
    dnn = g * kf[1];
    dnt = -g * kf[3];
    dtt = g * kf[4];
  }

  // the rate entering the law: the mean over the step of the normal rate's velocity part,
  // with this joint's damping integrated exponentially and its elastic force held; with a film,
  // the normal and the film's tangential rate together (the 2x2 form of "Oil film")
  mjtNum rate = rate_geo, rate_f = vtf_geo, fel = 0;
  if (delta > 0) {
    fel = cl_elastic_force(&c->lw, delta);
  }
  if (instep) {
    mjtNum ft_last = last ? s[B_FT] : 0.0;
    mjtNum cd = delta > 0 ? cl_law_damping(&c->lw, delta, fel, vin) : 0.0;
    if (!film) {
      mjtNum phi1, psi;
      cl_exponential_means(h * w_nn * cd, &phi1, &psi);
      rate = (rate_geo - 0.5 * kin_n) * phi1 + (other_n + kin_n - h * w_nn * fel + h * w_nt * ft_last) * psi;
    } else {
      // held forces on the journal along (n, f): -F_el + F_0n, F_0t; damping K = D + diag(C, 0);
      // the Couette torques (held) move the rates too: their response through W on the rows
      mjtNum hn = -fel + f0n, ht = f0t;
      mjtNum W[4] = {w_nn, w_nf, w_nf, w_ff};
      mjtNum K[4] = {dnn + cd, dnt, dnt, dtt};
      mjtNum couette = c->film.couette * spin / sqrt(1.0 - ratio * ratio);
      mjtNum* torque = c->scratch;
      for (int i = 0; i < nv; i++) {
        torque[i] = couette * (c->vec_rb[i] - c->vec_rj[i]);
      }
      mj_solveM(m, d, c->own_film, torque, 1);
      if (neq) cl_constrain(&c->eq, neq, nv, c->own_film);
      mjtNum an = other_n + kin_n + h * (w_nn * hn + w_nf * ht + w_nt * ft_last + mju_dot(jn, c->own_film, nv));
      mjtNum af = other_f + kin_f +
                  h * (w_nf * hn + w_ff * ht + w_tf * ft_last + mju_dot(c->vec_tf, c->own_film, nv));
      mjtNum Phi[4], Psi[4];
      cl_exponential_means2(h, W, K, Phi, Psi);
      mjtNum r0 = rate_geo - 0.5 * kin_n, f0 = vtf_geo - 0.5 * kin_f;  // at the step's start
      rate = Phi[0] * r0 + Phi[1] * f0 + Psi[0] * an + Psi[1] * af;
      rate_f = Phi[2] * r0 + Phi[3] * f0 + Psi[2] * an + Psi[3] * af;
    }
  }
  mjtNum fn = cl_normal_force(&c->lw, delta, fel, rate, vin);

  // the film's force at the rates (F_0 - D rate) and its shear torques
  mjtNum ffn = 0, fft = 0, tj = 0, tb = 0, film_power = 0;
  if (film) {
    ffn = f0n - (dnn * rate + dnt * rate_f);
    fft = f0t - (dnt * rate + dtt * rate_f);
    mjtNum couette = c->film.couette * spin / sqrt(1.0 - ratio * ratio);
    mjtNum moment = ecc * fft;  // e x F about z
    tj = -couette - 0.5 * moment;
    tb = couette - 0.5 * moment;
    // power of the film on the two bodies (the fluid takes no energy): F.e_dot + T_J w_J +
    // T_B w_B = F_n rate + F_t rate_f - couette spin - moment spin / 2, at the step's mean rates
    film_power = ffn * rate + fft * rate_f - couette * spin - 0.5 * moment * spin;
    if (instep) {  // its generalized force, then h M^-1 of it
      mjtNum* force = c->scratch;  // free again once the rows are made
      for (int i = 0; i < nv; i++) {
        force[i] = ffn * jn[i] + fft * (c->vec_tf[i] + ecc * c->vec_rb[i]) +
                   tj * c->vec_rj[i] + tb * c->vec_rb[i];
      }
      mj_solveM(m, d, c->own_film, force, 1);
      if (neq) cl_constrain(&c->eq, neq, nv, c->own_film);
      mju_scl(c->own_film, c->own_film, h, nv);
    }
  }

  // friction at the tangential velocity it leaves at the step's end (semi-implicit), or at
  // the sampled one (RK4)
  mjtNum vt = vt_geo, ft = 0;
  if (c->fr.mu != 0 && fn > 0) {
    if (instep) {
      mjtNum v_free = vt_geo + other_t - h * w_nt * fn + (film ? mju_dot(jt, c->own_film, nv) : 0.0);
      mjtNum v_end = cl_implicit_sliding_velocity(&c->fr, v_free, h * w_tt * c->fr.mu * fn);
      ft = cl_friction_force(&c->fr, fn, v_end);
      vt = 0.5 * (vt_geo + v_end);
    } else {
      ft = cl_friction_force(&c->fr, fn, vt_geo);
    }
  }

  if (instep) {  // this joint's own velocity change over the step, h M^-1 J' f
    for (int i = 0; i < nv; i++) {
      c->own[i] = h * (ft * c->ut[i] - fn * c->un[i]) + (film ? c->own_film[i] : 0.0);
    }
  }

  ev->time = d->time;
  ev->valid = 1;
  ev->delta = delta;
  ev->rate_geo = rate_geo;
  ev->rate = rate;
  ev->vt_geo = vt_geo;
  ev->vtf_geo = vtf_geo;
  ev->vin = vin;
  ev->fn = fn;
  ev->ft = ft;
  ev->fel = fel;
  ev->ecc = ecc;
  ev->film_n = ffn;
  ev->film_t = fft;
  ev->torque_j = tj;
  ev->torque_b = tb;
  mju_copy3(ev->axis, z);
  ev->power = (delta > 0 ? (fn - fel) * rate - ft * vt : 0.0) - film_power;
}

// add the contact force to qfrc_passive: f on the journal at P_J, -f on the bearing at P_B; a
// film's force through the two centres and its shear torques
static void apply(const mjModel* m, mjData* d, const jbData* c, const jbEval* ev) {
  if (ev->fn != 0 || ev->ft != 0) {
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
  if (c->film.model != FILM_NONE) {
    mjtNum f[3], g[3], tj[3], tb[3];
    mju_scl3(f, ev->normal, ev->film_n);
    mju_addToScl3(f, ev->tangent, ev->film_t);
    mju_scl3(g, f, -1.0);
    mju_scl3(tj, ev->axis, ev->torque_j);
    mju_scl3(tb, ev->axis, ev->torque_b);
    if (c->journal_body) {
      mj_applyFT(m, d, f, tj, d->site_xpos + 3 * c->journal_site, c->journal_body,
                 d->qfrc_passive);
    }
    if (c->bearing_body) {
      mj_applyFT(m, d, g, tb, d->site_xpos + 3 * c->bearing_site, c->bearing_body,
                 d->qfrc_passive);
    }
  }
}


// keep an evaluation made at d's state (with the vectors the in-step treatment left in c)
static void store(const mjModel* m, const mjData* d, jbData* c, const jbEval* ev) {
  int slot = cl_cache_slot(c->cache, sizeof(jbEval), CL_NCACHE, ev->time, &c->cache_next);
  c->cache[slot] = *ev;
  if (cl_semi_implicit(m)) {
    int nv = m->nv;
    mjtNum* v = c->slot_vec + 3 * nv * slot;
    mju_copy(v, d->qvel, nv);
    mju_copy(v + nv, c->own, nv);
    mju_copy(v + 2 * nv, c->vec_n, nv);
  }
}

// the cache slot holding the evaluation made one step before `time`, or -1
static int step_start_slot(const jbData* c, mjtNum time, mjtNum h) {
  const jbEval* ev = (const jbEval*)cl_cache_step_start(c->cache, sizeof(jbEval), CL_NCACHE, time, h);
  return ev ? (int)(ev - c->cache) : -1;
}

static void clear_cache(jbData* c) {
  for (int i = 0; i < CL_NCACHE; i++) {
    c->cache[i].valid = 0;
  }
  c->cache_next = 0;
}


//---------------------------------- plugin callbacks ----------------------------------------------

// the cache slot evaluated at d's time, velocities and eccentricity (semi-implicit integrators,
// where an evaluation costs Jacobians and solves), or -1: a sensor reads it instead of
// evaluating the same state again
static int same_state_slot(const mjModel* m, const mjData* d, const jbData* c) {
  if (!cl_semi_implicit(m)) {
    return -1;
  }
  int nv = m->nv;
  mjtNum dist[3], e[3];
  const mjtNum* mat = d->site_xmat + 9 * c->bearing_site;
  mjtNum z[3] = {mat[2], mat[5], mat[8]};
  mju_sub3(dist, d->site_xpos + 3 * c->journal_site, d->site_xpos + 3 * c->bearing_site);
  mju_addScl3(e, dist, z, -mju_dot3(dist, z));
  mjtNum ecc = mju_norm3(e);
  for (int i = 0; i < CL_NCACHE; i++) {
    const jbEval* ev = c->cache + i;
    if (ev->valid && ev->time == d->time && ev->ecc == ecc &&
        !memcmp(c->slot_vec + 3 * nv * i, d->qvel, sizeof(mjtNum) * nv)) {
      return i;
    }
  }
  return -1;
}

static int jb_nstate(const mjModel* m, int instance) {
  return B_OTHER + 2 * m->nv;
}


static int jb_nsensordata(const mjModel* m, int instance, int sensor_id) {
  return JB_NSENSOR;
}

static void jb_free(jbData* c) {
  free(c->sensor_adr);
  free(c->vec_n);
  cl_equality_free(&c->eq);
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
  c->sensor_adr = cl_instance_sensors(m, instance, &c->nsensor);
  int nv = m->nv > 0 ? m->nv : 1;
  c->vec_n = (mjtNum*)calloc((size_t)(22 + 3 * CL_NCACHE) * nv, sizeof(mjtNum));
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
  c->vec_tf = c->vec_n + 17 * nv;
  c->u_tf = c->vec_n + 18 * nv;
  c->vec_rj = c->vec_n + 19 * nv;
  c->vec_rb = c->vec_n + 20 * nv;
  c->own_film = c->vec_n + 21 * nv;
  c->slot_vec = c->vec_n + 22 * nv;
  if (!cl_equality_init(m, &c->eq)) {
    jb_free(c);
    mju_warning(JB_NAME " instance %d: out of memory", instance);
    return -1;
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
    mju_copy(to->slot_vec, from->slot_vec, 3 * CL_NCACHE * m->nv);
  }
}

static void jb_reset(const mjModel* m, mjtNum* plugin_state, void* plugin_data, int instance) {
  mju_zero(plugin_state, B_OTHER + 2 * m->nv);
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
      cl_elastic_energy(&c->lw, ev.delta, ev.fel),
      s[B_WORK], ev.ecc, ev.film_n, ev.film_t
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
    s[B_RATE0] = ev->rate_geo;
    s[B_RATEF0] = ev->vtf_geo;
    if (cl_semi_implicit(m)) {
      // the step's velocity change: what this joint's force did, the rest (other forces),
      // and the rate at the evaluation's time (the mean of the step's start and end rates)
      int nv = m->nv;
      const mjtNum* v = c->slot_vec + 3 * nv * slot;
      mjtNum half = 0;
      for (int i = 0; i < nv; i++) {
        mjtNum dv = d->qvel[i] - v[i];
        s[B_OTHER + i] = dv - v[nv + i];
        s[B_OTHER + nv + i] = dv;
        half += v[2 * nv + i] * dv;
      }
      s[B_RATE] += 0.5 * half;
    }
    s[B_HAVE] = 1.0;
    s[B_NSTEP] += 1.0;
  }
  clear_cache(c);
}


//---------------------------------- registration --------------------------------------------------

void cl_register_journal_bearing(void) {
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
}
