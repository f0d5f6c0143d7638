// What the compiled contacts' in-step treatment shares (journal_bearing.c's header, "In-step
// treatment"): Ambrosio's friction and its backward-Euler velocity, and the joint's own response
// with the model's equality constraints acting as the constraint solver solves them alone.

#ifndef CLEARANCE_INSTEP_H_
#define CLEARANCE_INSTEP_H_

#include <mujoco/mujoco.h>

// Ambrosio's friction: F_t = -mu c_d(|v|) F_n sign(v), c_d = clip((|v| - v0) / (v1 - v0), 0, 1)
typedef struct {
  mjtNum mu, v0, v1;
} clFriction;

// read friction (default 0), v0 (1e-4), v1 (1e-3) into *fr; 0 on failure (a warning says why)
int cl_configure_friction(const mjModel* m, int instance, clFriction* fr);

// Ambrosio friction at v_t, the operations of laws._friction
mjtNum cl_friction_force(const clFriction* fr, mjtNum fn, mjtNum vt);

// the tangential velocity v at the step's end that friction evaluated there gives:
// v + kk ramp(v) = v_free, kk = h w_tt mu F_n >= 0 (ramp(v) = c_d(|v|) sign(v)); the left side
// increases with v, so the root is unique, and each piece of the ramp is linear
mjtNum cl_implicit_sliding_velocity(const clFriction* fr, mjtNum v_free, mjtNum kk);

// the equality constraints' rows of a model, at most `max` of them, and their response
typedef struct {
  int max;        // connect 3, weld 6, joint and tendon couplings 1 each; <= 0: none or other kinds
  mjtNum* rows;   // their Jacobian rows (max nv)
  mjtNum* y;      // M^-1 of each row (max nv)
  mjtNum* a;      // J_c M^-1 J_c' + R, then its Cholesky factor (max^2)
  mjtNum* z;      // solves (2 max)
} clEquality;

// allocate for the model's equality constraints; 0 when out of memory
int cl_equality_init(const mjModel* m, clEquality* eq);
void cl_equality_free(clEquality* eq);

// The equality constraints' rows at this state and the Cholesky factor of J_c M^-1 J_c' + R;
// returns their count k, or 0 (none, more than the model declares, or singular: responses stay
// free). See cl_constrain.
int cl_equality_factor(const mjModel* m, mjData* d, clEquality* eq);

// Turn a free response u = M^-1 f into the response with the equality constraints' rows acting
// as the constraint solver solves them alone (their soft dynamics at this state):
// u -= Y (J_c M^-1 J_c' + R)^-1 J_c u, Y = M^-1 J_c'. A loop closure or a pin held by a connect
// then moves as the loop lets it, not as the free tree would.
void cl_constrain(const clEquality* eq, int k, int nv, mjtNum* u);

// For k coupled rates r' = A - (1/h) G r over a step h with G = h W D (W symmetric positive
// semi-definite k x k, row-major; D = diag(damping), every damping > 0; k <= 4), the matrices
// Phi = phi1(-G) and Psi = psi(G) (cl_exponential_means on G), so that the mean of r over the
// step is Phi r0 + h Psi A: through the symmetric Gs = h D^1/2 W D^1/2 (Jacobi's eigenvalue
// method), f(G) = D^-1/2 f(Gs) D^1/2.
void cl_exponential_means_diag(int k, mjtNum h, const mjtNum* W, const mjtNum* damping,
                               mjtNum* Phi, mjtNum* Psi);

#endif  // CLEARANCE_INSTEP_H_
