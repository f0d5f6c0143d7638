// The normal contact laws of the compiled contacts: the single source is
// contact_calibration/laws.py, reproduced here operation by operation (tests compare them).

#ifndef CLEARANCE_CONTACT_LAWS_H_
#define CLEARANCE_CONTACT_LAWS_H_

#include <mujoco/mujoco.h>

// contact laws, in the order of clearance.model.ContactLaw
enum {
  LAW_HERTZ = 0, LAW_LN, LAW_HC, LAW_FLORES, LAW_GONTHIER, LAW_HU_GUO, LAW_IMPACT, LAW_COUNT
};

// a joint's normal law and its parameters
typedef struct {
  int law;                 // LAW_*
  mjtNum stiffness;        // K [N/m^n]
  mjtNum exponent;         // n
  mjtNum restitution;      // c_e (1 for Hertz and IMPACT)
  mjtNum chi;              // hysteresis factor chi(c_e) (0 for Hertz and IMPACT)
  mjtNum c_max, d_max;     // IMPACT's maximum damping [N s/m] and full-damping depth [m]
} clLaw;

// hysteresis factor chi(c_e), the expressions of laws.hysteresis_factor
mjtNum cl_hysteresis(int law, mjtNum e);

// read and validate the attributes law, stiffness, exponent, restitution, c_max, d_max into
// *lw; 0 on failure (a warning says why)
int cl_configure_law(const mjModel* m, int instance, clLaw* lw);

// normal force of the law at penetration delta > 0, rate delta_dot and approach speed v_in
// (the operations of laws.normal_force); *fel receives the elastic part K delta^n; 0 for
// delta <= 0
mjtNum cl_normal_force(const clLaw* lw, mjtNum delta, mjtNum rate, mjtNum vin, mjtNum* fel);

// the law's damping coefficient dF_n/d(delta_dot) [N s/m] at delta > 0 (0: Hertz), given the
// elastic part fel
mjtNum cl_law_damping(const clLaw* lw, mjtNum delta, mjtNum fel, mjtNum vin);

#endif  // CLEARANCE_CONTACT_LAWS_H_
