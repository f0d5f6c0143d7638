// clearance.slider_guide: exact contact of a slider with play in its guide (a translational
// clearance joint; clearance/translational.py, reference/corner_contact.py).
//
// A MuJoCo engine plugin (capabilities mjPLUGIN_PASSIVE | mjPLUGIN_SENSOR), one instance per
// joint. The slider is a block of length L and height H whose centre is the slider site (its x
// axis along the block's length, y across); the guide is two lines at +-(H/2 + c) from its centre
// line through the guide site (its x axis u along the guide, y = n, z the plane's normal).
// Corner k sits at (s_u L/2, s_n H/2) in the slider site's axes, (s_u, s_n) = CORNERS[k] of
// clearance.translational (0 = (-,+), 1 = (+,+), 2 = (-,-), 3 = (+,-)). Each corner is its own
// contact point (Flores, Ambrosio, Claro and Lankarani 2008), with exact geometry against either
// line: with s = n.(P - G) the corner's distance across the centre line,
//   delta = |s| - (H/2 + c),  delta_dot = sign(s) n.(v_P - v_G(P)),  v_t = u.(v_P - v_G(P))
// (v_G(P) the guide's material velocity at P), and the force on the slider at P is
// F = -sign(s) F_n n + F_t u, -F on the guide at P. F_n is the joint's point law (contact_laws.c,
// the operations of laws.normal_force) with the corner's approach speed recorded at its onset
// (located inside the step, as the journal bearing does) and F_t Ambrosio's friction.
//
// In-step treatment: the journal bearing's (journal_bearing.c's header: "In-step treatment",
// "Normal force", "Kinematic forcing", "Friction near rest"), per corner, with the corners' own
// responses coupled: the rows J_k (normal rates) and T_k (tangential velocities) over the dofs,
// W = J M^-1 J' with the equality constraints (instep.h), the other forces' last velocity change
// and each rate's kinematic change from history; the damped corners' normal rates integrated
// together (cl_exponential_means_diag: r' = A - (1/h) h W_AA diag(C_A) r over the corners A whose
// law damps), the held forces (elastic, last friction) in A; friction per corner at the
// tangential velocity it leaves at the step's end, the other corners' forces in its free
// velocity. RK4 takes the rates as they are.
//
// State (nstate = 4 + 7 * 4 + 2 nv): [0] time of the last sample, [1] 1 once a sample is
// recorded, [2] dissipated work so far [J], [3] steps; per corner k at 4 + 7 k: delta, rate at
// the sample's time, sampled rate, friction force, 1 in an impact, approach speed, side sign(s);
// then the last step's velocity change from the other forces (nv) and its whole change (nv).
//
// Sensor output (nsensordata = 24): per corner k: F_n [N] (>= 0), F_t [N] (on the slider along
// u), delta [m], delta_dot entering the law [m/s], v_in [m/s] (20 values); then the contact case
// (clearance.translational.SliderContact: 0 free, 1 one corner, 2 one side, 3 diagonal), the
// contact potential energy [J], the dissipated work [J], the tilt [rad] (the slider site's x axis
// from u, about z).
//
// Config attributes: slider_site, guide_site; clearance c [m] > 0; slider_length L [m] > 0,
// slider_height H [m] > 0; law, stiffness, exponent, restitution, c_max, d_max as the journal
// bearing's point laws; friction, v0, v1; min_approach_speed.

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <mujoco/mjplugin.h>
#include <mujoco/mujoco.h>

#include "contact_laws.h"
#include "instep.h"
#include "plugin_util.h"

#define SG_NAME "clearance.slider_guide"
#define SG_NSENSOR 24
#define SG_NC 4     // corners
#define SG_CS 7     // state values per corner

enum { G_TIME = 0, G_HAVE, G_WORK, G_NSTEP, G_CORNER };
enum { K_DELTA = 0, K_RATE, K_RATE0, K_FT, K_CONTACT, K_VIN, K_SIDE };

static const mjtNum kCorner[SG_NC][2] = {{-0.5, 0.5}, {0.5, 0.5}, {-0.5, -0.5}, {0.5, -0.5}};

static const char* const kSliderAttributes[] = {
  "slider_site", "guide_site", "clearance", "slider_length", "slider_height", "law",
  "stiffness", "exponent", "restitution", "c_max", "d_max", "friction", "v0", "v1",
  "min_approach_speed"
};

// one force evaluation of the four corners
typedef struct {
  mjtNum time;       // d->time of the evaluation
  int valid;
  mjtNum delta[SG_NC], rate_geo[SG_NC], rate[SG_NC], vt_geo[SG_NC], vin[SG_NC];
  mjtNum fn[SG_NC], ft[SG_NC], fel[SG_NC], side[SG_NC];
  mjtNum point[SG_NC][3];  // the corners (world)
  mjtNum normal[3], axis[3];  // n and u of the guide (world)
  mjtNum power;      // dissipated power [W]
  mjtNum tilt;
} sgEval;

typedef struct {
  int slider_site, guide_site, slider_body, guide_body;
  mjtNum clearance, length, height;
  clLaw lw;
  clFriction fr;
  mjtNum min_speed;
  int nsensor;
  int* sensor_adr;
  sgEval cache[CL_NCACHE];
  int cache_next;
  clEquality eq;
  // one block, allocated in init: rows (8 nv: J_0..3 then T_0..3), responses (8 nv), own (nv),
  // scratch (18 nv), per cache slot qvel, own and J_0..3 (6 nv each)
  mjtNum *rows, *resp, *own, *scratch, *slot_vec;
} sgData;

static int sg_configure(const mjModel* m, int instance, sgData* c) {
  static const mjtNum kMinSpeed = 1e-3;
  if (!cl_read_site(m, instance, "slider_site", &c->slider_site) ||
      !cl_read_site(m, instance, "guide_site", &c->guide_site)) {
    return 0;
  }
  c->slider_body = m->site_bodyid[c->slider_site];
  c->guide_body = m->site_bodyid[c->guide_site];
  if (c->slider_body == c->guide_body) {
    mju_warning(SG_NAME " instance %d: slider_site and guide_site are on the same body", instance);
    return 0;
  }
  return cl_read_number(m, instance, "clearance", NULL, &c->clearance) &&
         cl_check(m, c->clearance > 0, instance, "clearance", c->clearance, "> 0 [m]") &&
         cl_read_number(m, instance, "slider_length", NULL, &c->length) &&
         cl_check(m, c->length > 0, instance, "slider_length", c->length, "> 0 [m]") &&
         cl_read_number(m, instance, "slider_height", NULL, &c->height) &&
         cl_check(m, c->height > 0, instance, "slider_height", c->height, "> 0 [m]") &&
         cl_configure_law(m, instance, &c->lw) &&
         c->lw.law <= LAW_IMPACT &&  // the point laws
         cl_configure_friction(m, instance, &c->fr) &&
         cl_read_number(m, instance, "min_approach_speed", &kMinSpeed, &c->min_speed) &&
         cl_check(m, c->min_speed > 0, instance, "min_approach_speed", c->min_speed, "> 0 [m/s]");
}

// point Jacobian (3 x nv) of a body at p, from the body's Jacobians at o: Jp(o) + Jr x (p - o)
static void point_jacobian(int nv, const mjtNum* jp, const mjtNum* jr, const mjtNum r[3],
                           mjtNum* out) {
  for (int i = 0; i < nv; i++) {
    mjtNum w[3] = {jr[i], jr[nv + i], jr[2 * nv + i]}, x[3];
    mju_cross(x, w, r);
    out[i] = jp[i] + x[0];
    out[nv + i] = jp[nv + i] + x[1];
    out[2 * nv + i] = jp[2 * nv + i] + x[2];
  }
}

static void sg_evaluate(const mjModel* m, mjData* d, sgData* c, const mjtNum* s, sgEval* ev) {
  int nv = m->nv, instep = cl_semi_implicit(m);
  int last = cl_is_last_step(m, d, s[G_HAVE], s[G_TIME]);
  mjtNum h = m->opt.timestep;
  const mjtNum* ps = d->site_xpos + 3 * c->slider_site;
  const mjtNum* rs = d->site_xmat + 9 * c->slider_site;
  const mjtNum* pg = d->site_xpos + 3 * c->guide_site;
  const mjtNum* rg = d->site_xmat + 9 * c->guide_site;
  mjtNum u[3] = {rg[0], rg[3], rg[6]}, nw[3] = {rg[1], rg[4], rg[7]};
  mju_copy3(ev->normal, nw);
  mju_copy3(ev->axis, u);
  mjtNum xs[3] = {rs[0], rs[3], rs[6]};
  ev->tilt = atan2(mju_dot3(xs, nw), mju_dot3(xs, u));
  mjtNum half = 0.5 * c->height + c->clearance;

  // the bodies' Jacobians at the two sites (rows over the dofs), then each corner's
  mjtNum *js = c->scratch, *jsr = c->scratch + 3 * nv, *jg = c->scratch + 6 * nv,
         *jgr = c->scratch + 9 * nv;
  mjtNum* pjs = c->scratch + 12 * nv;  // one corner's point Jacobians (3 nv each)
  mjtNum* pjg = c->scratch + 15 * nv;
  mj_jac(m, d, js, jsr, ps, c->slider_body);
  mj_jac(m, d, jg, jgr, pg, c->guide_body);
  mjtNum vt0[SG_NC], r0[SG_NC];
  for (int k = 0; k < SG_NC; k++) {
    mjtNum* p = ev->point[k];
    for (int a = 0; a < 3; a++) {
      p[a] = ps[a] + kCorner[k][0] * c->length * (a == 0 ? rs[0] : a == 1 ? rs[3] : rs[6]) +
             kCorner[k][1] * c->height * (a == 0 ? rs[1] : a == 1 ? rs[4] : rs[7]);
    }
    mjtNum rel[3];
    mju_sub3(rel, p, pg);
    mjtNum across = mju_dot3(nw, rel);
    ev->side[k] = across >= 0 ? 1.0 : -1.0;
    ev->delta[k] = mju_abs(across) - half;
    mjtNum rsl[3], rgl[3];
    mju_sub3(rsl, p, ps);
    mju_sub3(rgl, p, pg);
    point_jacobian(nv, js, jsr, rsl, pjs);
    point_jacobian(nv, jg, jgr, rgl, pjg);
    mjtNum* jk = c->rows + k * nv;
    mjtNum* tk = c->rows + (SG_NC + k) * nv;
    for (int i = 0; i < nv; i++) {
      mjtNum dv[3] = {pjs[i] - pjg[i], pjs[nv + i] - pjg[nv + i],
                      pjs[2 * nv + i] - pjg[2 * nv + i]};
      jk[i] = ev->side[k] * mju_dot3(nw, dv);
      tk[i] = mju_dot3(u, dv);
    }
    r0[k] = mju_dot(jk, d->qvel, nv);
    vt0[k] = mju_dot(tk, d->qvel, nv);
    ev->rate_geo[k] = r0[k];
    ev->vt_geo[k] = vt0[k];
  }

  // own responses (with the equality constraints), other forces and kinematic forcing
  mjtNum Wnn[SG_NC * SG_NC] = {0}, Wnt[SG_NC * SG_NC] = {0}, wtt[SG_NC] = {0};
  mjtNum other_n[SG_NC] = {0}, other_t[SG_NC] = {0}, kin[SG_NC] = {0};
  // the responses enter only through forces, and only a loaded corner (inside its line, or carrying
  // a friction force from the last step) has one this step: its normal and tangential rows are
  // solved, the others' are not needed (their columns of W multiply forces that are 0), so a slider
  // in free flight solves nothing and one landing on two corners half its rows; the same results
  int loaded[SG_NC], nloaded = 0;
  for (int k = 0; k < SG_NC; k++) {
    loaded[k] = ev->delta[k] > 0 || (last && s[G_CORNER + SG_CS * k + K_FT] != 0);
    nloaded += loaded[k];
  }
  if (instep && nloaded) {
    int neq = cl_equality_factor(m, d, &c->eq);
    for (int l = 0; l < SG_NC; l++) {
      if (!loaded[l]) continue;
      for (int r = l; r < 2 * SG_NC; r += SG_NC) {
        mj_solveM(m, d, c->resp + r * nv, c->rows + r * nv, 1);
        if (neq) cl_constrain(&c->eq, neq, nv, c->resp + r * nv);
      }
      for (int k = 0; k < SG_NC; k++) {
        Wnn[k * SG_NC + l] = mju_dot(c->rows + k * nv, c->resp + l * nv, nv);
        Wnt[k * SG_NC + l] = mju_dot(c->rows + k * nv, c->resp + (SG_NC + l) * nv, nv);
      }
      wtt[l] = mju_dot(c->rows + (SG_NC + l) * nv, c->resp + (SG_NC + l) * nv, nv);
    }
  }
  if (instep) {
    for (int k = 0; k < SG_NC; k++) {
      if (last) {
        other_n[k] = mju_dot(c->rows + k * nv, s + G_CORNER + SG_NC * SG_CS, nv);
        other_t[k] = mju_dot(c->rows + (SG_NC + k) * nv, s + G_CORNER + SG_NC * SG_CS, nv);
        const mjtNum* sk = s + G_CORNER + SG_CS * k;
        if (sk[K_SIDE] == ev->side[k]) {  // the same line: the sampled rates compare
          kin[k] = r0[k] - sk[K_RATE0] -
                   mju_dot(c->rows + k * nv, s + G_CORNER + SG_NC * SG_CS + nv, nv);
        }
      }
    }
  }

  // approach speeds, elastic forces and the laws' damping
  mjtNum cd[SG_NC], held[SG_NC];
  for (int k = 0; k < SG_NC; k++) {
    const mjtNum* sk = s + G_CORNER + SG_CS * k;
    mjtNum delta = ev->delta[k], rate_free = r0[k] + 0.5 * other_n[k], vin = 0;
    if (delta > 0) {
      if (sk[K_CONTACT] != 0 && sk[K_SIDE] == ev->side[k]) {
        vin = sk[K_VIN];
      } else if (sk[K_DELTA] <= 0 && sk[K_SIDE] == ev->side[k] &&
                 (instep ? last : cl_is_recent(m, d, s[G_HAVE], s[G_TIME]))) {
        mjtNum theta = sk[K_DELTA] / (sk[K_DELTA] - delta);
        vin = sk[K_RATE] + theta * (rate_free - sk[K_RATE]);
      } else {
        vin = rate_free;
      }
      vin = vin > c->min_speed ? vin : c->min_speed;
    }
    ev->vin[k] = vin;
    ev->fel[k] = delta > 0 ? cl_elastic_force(&c->lw, delta) : 0.0;
    cd[k] = delta > 0 ? cl_law_damping(&c->lw, delta, ev->fel[k], vin) : 0.0;
    held[k] = -ev->fel[k];  // the elastic force along the row, held over the step
  }

  // the rates entering the laws
  for (int k = 0; k < SG_NC; k++) ev->rate[k] = r0[k];
  if (instep) {
    mjtNum hA[SG_NC], start[SG_NC];
    for (int k = 0; k < SG_NC; k++) {
      hA[k] = other_n[k] + kin[k];
      for (int l = 0; l < SG_NC; l++) {
        const mjtNum* sl = s + G_CORNER + SG_CS * l;
        hA[k] += h * (Wnn[k * SG_NC + l] * held[l] + Wnt[k * SG_NC + l] * (last ? sl[K_FT] : 0.0));
      }
      start[k] = r0[k] - 0.5 * kin[k];
      ev->rate[k] = start[k] + 0.5 * hA[k];  // undamped: the plain mean
    }
    int act[SG_NC], na = 0;
    for (int k = 0; k < SG_NC; k++) {
      if (cd[k] > 0) act[na++] = k;
    }
    if (na) {
      mjtNum W[16], D[4], Phi[16], Psi[16];
      for (int a = 0; a < na; a++) {
        D[a] = cd[act[a]];
        for (int b = 0; b < na; b++) W[a * na + b] = Wnn[act[a] * SG_NC + act[b]];
      }
      cl_exponential_means_diag(na, h, W, D, Phi, Psi);
      for (int a = 0; a < na; a++) {
        mjtNum r = 0;
        for (int b = 0; b < na; b++) {
          r += Phi[a * na + b] * start[act[b]] + Psi[a * na + b] * hA[act[b]];
        }
        ev->rate[act[a]] = r;
      }
    }
  }

  // normal forces, then friction at the tangential velocity it leaves at the step's end
  ev->power = 0;
  for (int k = 0; k < SG_NC; k++) {
    ev->fn[k] = cl_normal_force(&c->lw, ev->delta[k], ev->fel[k], ev->rate[k], ev->vin[k]);
  }
  for (int k = 0; k < SG_NC; k++) {
    mjtNum vt = vt0[k], ft = 0;
    if (c->fr.mu != 0 && ev->fn[k] > 0) {
      if (instep) {
        mjtNum v_free = vt0[k] + other_t[k];
        for (int l = 0; l < SG_NC; l++) v_free -= h * Wnt[l * SG_NC + k] * ev->fn[l];
        mjtNum v_end = cl_implicit_sliding_velocity(&c->fr, v_free, h * wtt[k] * c->fr.mu * ev->fn[k]);
        ft = cl_friction_force(&c->fr, ev->fn[k], v_end);
        vt = 0.5 * (vt0[k] + v_end);
      } else {
        ft = cl_friction_force(&c->fr, ev->fn[k], vt0[k]);
      }
    }
    ev->ft[k] = ft;
    if (ev->delta[k] > 0) ev->power += (ev->fn[k] - ev->fel[k]) * ev->rate[k] - ft * vt;
  }

  if (instep) {  // the own velocity change over the step, h M^-1 sum(J' f)
    mju_zero(c->own, nv);
    for (int k = 0; k < SG_NC; k++) {
      if (!loaded[k]) continue;
      mju_addToScl(c->own, c->resp + k * nv, -h * ev->fn[k], nv);
      mju_addToScl(c->own, c->resp + (SG_NC + k) * nv, h * ev->ft[k], nv);
    }
  }
  ev->time = d->time;
  ev->valid = 1;
}

static void sg_apply(const mjModel* m, mjData* d, const sgData* c, const sgEval* ev) {
  for (int k = 0; k < SG_NC; k++) {
    if (ev->fn[k] == 0 && ev->ft[k] == 0) continue;
    mjtNum f[3], g[3];
    mju_scl3(f, ev->normal, -ev->side[k] * ev->fn[k]);
    mju_addToScl3(f, ev->axis, ev->ft[k]);
    mju_scl3(g, f, -1.0);
    if (c->slider_body) mj_applyFT(m, d, f, NULL, ev->point[k], c->slider_body, d->qfrc_passive);
    if (c->guide_body) mj_applyFT(m, d, g, NULL, ev->point[k], c->guide_body, d->qfrc_passive);
  }
}

static int sg_case(const sgEval* ev) {
  int on[SG_NC], count = 0;
  for (int k = 0; k < SG_NC; k++) {
    on[k] = ev->delta[k] > 0;
    count += on[k];
  }
  int upper = on[0] || on[1], lower = on[2] || on[3];
  if (upper && lower) return 3;
  if (count >= 2) return 2;
  return count;
}

//---------------------------------- plugin callbacks ----------------------------------------------

static int sg_nstate(const mjModel* m, int instance) {
  return G_CORNER + SG_NC * SG_CS + 2 * m->nv;
}

static int sg_nsensordata(const mjModel* m, int instance, int sensor_id) {
  return SG_NSENSOR;
}

static void sg_free(sgData* c) {
  free(c->sensor_adr);
  free(c->rows);
  cl_equality_free(&c->eq);
  free(c);
}

static int sg_init(const mjModel* m, mjData* d, int instance) {
  sgData* c = (sgData*)calloc(1, sizeof(sgData));
  if (!c) {
    mju_warning(SG_NAME " instance %d: out of memory", instance);
    return -1;
  }
  if (!sg_configure(m, instance, c)) {
    if (c->lw.law > LAW_IMPACT) {
      mju_warning(SG_NAME " instance %d: a slider's corners take the point laws only", instance);
    }
    free(c);
    return -1;
  }
  int nv = m->nv > 0 ? m->nv : 1;
  c->sensor_adr = cl_instance_sensors(m, instance, &c->nsensor);
  c->rows = (mjtNum*)calloc((size_t)(8 + 8 + 1 + 18 + 6 * CL_NCACHE) * nv, sizeof(mjtNum));
  if (!c->sensor_adr || !c->rows || !cl_equality_init(m, &c->eq)) {
    sg_free(c);
    mju_warning(SG_NAME " instance %d: out of memory", instance);
    return -1;
  }
  c->resp = c->rows + 8 * nv;
  c->own = c->rows + 16 * nv;
  c->scratch = c->rows + 17 * nv;
  c->slot_vec = c->rows + 35 * nv;
  d->plugin_data[instance] = (uintptr_t)c;
  return 0;
}

static void sg_destroy(mjData* d, int instance) {
  sgData* c = (sgData*)d->plugin_data[instance];
  if (c) sg_free(c);
  d->plugin_data[instance] = 0;
}

static void sg_clear(sgData* c) {
  for (int i = 0; i < CL_NCACHE; i++) c->cache[i].valid = 0;
  c->cache_next = 0;
}

static void sg_copy(mjData* dest, const mjModel* m, const mjData* src, int instance) {
  sgData* to = (sgData*)dest->plugin_data[instance];
  const sgData* from = (const sgData*)src->plugin_data[instance];
  if (to && from) {
    memcpy(to->cache, from->cache, sizeof(to->cache));
    to->cache_next = from->cache_next;
    mju_copy(to->slot_vec, from->slot_vec, 6 * CL_NCACHE * m->nv);
  }
}

static void sg_reset(const mjModel* m, mjtNum* plugin_state, void* plugin_data, int instance) {
  mju_zero(plugin_state, G_CORNER + SG_NC * SG_CS + 2 * m->nv);
  if (plugin_data) sg_clear((sgData*)plugin_data);
}

// the cache slot evaluated at d's time, velocities and corner geometry (semi-implicit integrators,
// where an evaluation costs Jacobians and solves), or -1: the sensor stage reads it instead of
// evaluating the passive stage's state again (as the journal bearing's same_state_slot)
static int sg_same_state_slot(const mjModel* m, const mjData* d, const sgData* c) {
  if (!cl_semi_implicit(m)) {
    return -1;
  }
  int nv = m->nv;
  const mjtNum* ps = d->site_xpos + 3 * c->slider_site;
  const mjtNum* rs = d->site_xmat + 9 * c->slider_site;
  const mjtNum* pg = d->site_xpos + 3 * c->guide_site;
  const mjtNum* rg = d->site_xmat + 9 * c->guide_site;
  mjtNum nw[3] = {rg[1], rg[4], rg[7]};
  mjtNum half = 0.5 * c->height + c->clearance;
  for (int i = 0; i < CL_NCACHE; i++) {
    const sgEval* ev = c->cache + i;
    if (!ev->valid || ev->time != d->time || memcmp(ev->normal, nw, sizeof(nw)) ||
        memcmp(c->slot_vec + 6 * nv * i, d->qvel, sizeof(mjtNum) * nv)) {
      continue;
    }
    int same = 1;
    for (int k = 0; k < SG_NC && same; k++) {  // the corners and their gaps, computed as sg_evaluate does
      mjtNum p[3], rel[3];
      for (int a = 0; a < 3; a++) {
        p[a] = ps[a] + kCorner[k][0] * c->length * (a == 0 ? rs[0] : a == 1 ? rs[3] : rs[6]) +
               kCorner[k][1] * c->height * (a == 0 ? rs[1] : a == 1 ? rs[4] : rs[7]);
      }
      mju_sub3(rel, p, pg);
      same = !memcmp(p, ev->point[k], sizeof(p)) && mju_abs(mju_dot3(nw, rel)) - half == ev->delta[k];
    }
    if (same) {
      return i;
    }
  }
  return -1;
}

static void sg_compute(const mjModel* m, mjData* d, int instance, int capability_bit) {
  sgData* c = (sgData*)d->plugin_data[instance];
  const mjtNum* s = d->plugin_state + m->plugin_stateadr[instance];
  sgEval ev;
  int same = (capability_bit & mjPLUGIN_PASSIVE) ? -1 : sg_same_state_slot(m, d, c);
  if (same >= 0) {
    ev = c->cache[same];  // the sensor stage after the passive stage of one forward pass
  } else {
    sg_evaluate(m, d, c, s, &ev);
  }
  if (capability_bit & mjPLUGIN_PASSIVE) {
    int slot = cl_cache_slot(c->cache, sizeof(sgEval), CL_NCACHE, ev.time, &c->cache_next);
    c->cache[slot] = ev;
    if (cl_semi_implicit(m)) {
      int nv = m->nv;
      mjtNum* v = c->slot_vec + 6 * nv * slot;
      mju_copy(v, d->qvel, nv);
      mju_copy(v + nv, c->own, nv);
      mju_copy(v + 2 * nv, c->rows, SG_NC * nv);
    }
    sg_apply(m, d, c, &ev);
  }
  if (capability_bit & mjPLUGIN_SENSOR) {
    mjtNum out[SG_NSENSOR];
    mjtNum potential = 0;
    for (int k = 0; k < SG_NC; k++) {
      out[5 * k] = ev.fn[k];
      out[5 * k + 1] = ev.ft[k];
      out[5 * k + 2] = ev.delta[k];
      out[5 * k + 3] = ev.rate[k];
      out[5 * k + 4] = ev.vin[k];
      potential += cl_elastic_energy(&c->lw, ev.delta[k], ev.fel[k]);
    }
    out[20] = sg_case(&ev);
    out[21] = potential;
    out[22] = s[G_WORK];
    out[23] = ev.tilt;
    for (int i = 0; i < c->nsensor; i++) mju_copy(d->sensordata + c->sensor_adr[i], out, SG_NSENSOR);
  }
}

static void sg_advance(const mjModel* m, mjData* d, int instance) {
  sgData* c = (sgData*)d->plugin_data[instance];
  mjtNum* s = d->plugin_state + m->plugin_stateadr[instance];
  mjtNum h = m->opt.timestep;
  const sgEval* ev = (const sgEval*)cl_cache_step_start(c->cache, sizeof(sgEval), CL_NCACHE,
                                                          d->time, h);
  if (ev) {
    int nv = m->nv, slot = (int)(ev - c->cache);
    const mjtNum* v = c->slot_vec + 6 * nv * slot;
    mjtNum* other = s + G_CORNER + SG_NC * SG_CS;
    if (cl_semi_implicit(m)) {
      for (int i = 0; i < nv; i++) {
        mjtNum dv = d->qvel[i] - v[i];
        other[i] = dv - v[nv + i];
        other[nv + i] = dv;
      }
    }
    for (int k = 0; k < SG_NC; k++) {
      mjtNum* sk = s + G_CORNER + SG_CS * k;
      sk[K_CONTACT] = ev->delta[k] > 0 ? 1.0 : 0.0;
      sk[K_VIN] = ev->delta[k] > 0 ? ev->vin[k] : 0.0;
      sk[K_DELTA] = ev->delta[k];
      sk[K_FT] = ev->ft[k];
      sk[K_RATE0] = ev->rate_geo[k];
      sk[K_SIDE] = ev->side[k];
      sk[K_RATE] = ev->rate_geo[k];
      if (cl_semi_implicit(m)) {  // the rate at the sample's time: the step's mean
        sk[K_RATE] += 0.5 * mju_dot(v + (2 + k) * nv, other + nv, nv);
      }
    }
    s[G_WORK] += h * ev->power;
    s[G_TIME] = ev->time;
    s[G_HAVE] = 1.0;
    s[G_NSTEP] += 1.0;
  }
  sg_clear(c);
}

void cl_register_slider_guide(void) {
  mjpPlugin plugin;
  mjp_defaultPlugin(&plugin);
  plugin.name = SG_NAME;
  plugin.capabilityflags |= mjPLUGIN_PASSIVE | mjPLUGIN_SENSOR;
  plugin.needstage = mjSTAGE_VEL;
  plugin.nattribute = sizeof(kSliderAttributes) / sizeof(kSliderAttributes[0]);
  plugin.attributes = kSliderAttributes;
  plugin.nstate = sg_nstate;
  plugin.nsensordata = sg_nsensordata;
  plugin.init = sg_init;
  plugin.destroy = sg_destroy;
  plugin.copy = sg_copy;
  plugin.reset = sg_reset;
  plugin.compute = sg_compute;
  plugin.advance = sg_advance;
  mjp_registerPlugin(&plugin);
}
