// The normal contact laws of the compiled contacts: the single source is
// contact_calibration/laws.py, reproduced here operation by operation (tests compare them).

#ifndef CLEARANCE_CONTACT_LAWS_H_
#define CLEARANCE_CONTACT_LAWS_H_

#include <mujoco/mujoco.h>

// contact laws, in the order of clearance.model.ContactLaw: the point laws, then the
// cylindrical (conformal) laws of contact_calibration/cylindrical_laws.py
enum {
  LAW_HERTZ = 0, LAW_LN, LAW_HC, LAW_FLORES, LAW_GONTHIER, LAW_HU_GUO, LAW_IMPACT,
  LAW_JOHNSON, LAW_RADZIMOVSKY, LAW_GOLDSMITH, LAW_DUBOWSKY_FREUDENSTEIN, LAW_ESDU_78035,
  LAW_LIU, LAW_PEREIRA, LAW_PERSSON, LAW_COUNT
};

// a joint's normal law and its parameters
typedef struct {
  int law;                 // LAW_*
  mjtNum stiffness;        // K [N/m^n]
  mjtNum exponent;         // n
  mjtNum restitution;      // c_e (1 for Hertz and IMPACT)
  mjtNum chi;              // hysteresis factor chi(c_e) (0 for Hertz and IMPACT)
  mjtNum c_max, d_max;     // IMPACT's maximum damping [N s/m] and full-damping depth [m]
  // the cylindrical laws' constants (cylindrical_laws.CylinderLaw, computed in Python): the
  // logarithmic laws' compliance k [m/N], reference force F0 [N] and offset beta; LIU and
  // PERSSON's stiffness S in `stiffness` (PEREIRA's K and n in stiffness and exponent); the
  // clearance c [m]; the deepest penetration delta* [m] the law gives a force for
  mjtNum compliance, reference_force, offset, clearance, max_penetration;
} clLaw;

// hysteresis factor chi(c_e), the expressions of laws.hysteresis_factor
mjtNum cl_hysteresis(int law, mjtNum e);

// read and validate the attributes law, stiffness, exponent, restitution, c_max, d_max into
// *lw; 0 on failure (a warning says why)
int cl_configure_law(const mjModel* m, int instance, clLaw* lw);

// elastic force F_el(delta) [N]: 0 for delta <= 0, +inf beyond a cylindrical law's delta*
// (cylindrical_laws.elastic_force; K delta^n for the point laws)
mjtNum cl_elastic_force(const clLaw* lw, mjtNum delta);

// normal force of the law at penetration delta > 0, elastic force fel = cl_elastic_force,
// rate delta_dot and approach speed v_in (the operations of laws.normal_force); 0 for
// delta <= 0
mjtNum cl_normal_force(const clLaw* lw, mjtNum delta, mjtNum fel, mjtNum rate, mjtNum vin);

// the elastic energy stored at delta [J] (cylindrical_laws.elastic_energy; K delta^(n+1)/(n+1))
mjtNum cl_elastic_energy(const clLaw* lw, mjtNum delta, mjtNum fel);

// the law's damping coefficient dF_n/d(delta_dot) [N s/m] at delta > 0 (0: Hertz), given the
// elastic part fel
mjtNum cl_law_damping(const clLaw* lw, mjtNum delta, mjtNum fel, mjtNum vin);

#endif  // CLEARANCE_CONTACT_LAWS_H_
