// The oil film of a lubricated journal bearing, for clearance.journal_bearing: the short
// (Ocvirk) and long (Sommerfeld, Pinkus-Sternlicht) pi-film forces of
// contact_calibration/film.py, reproduced operation by operation (film_terms, film_scalar),
// and the 2x2 exponential means the in-step treatment integrates the film's damping with.

#ifndef CLEARANCE_FILM_H_
#define CLEARANCE_FILM_H_

#include <mujoco/mujoco.h>

enum { FILM_NONE = 0, FILM_SHORT, FILM_LONG };

// a joint's film, prepared (film.py's FilmParameters)
typedef struct {
  int model;           // FILM_*
  mjtNum scale;        // S [N s]: mu R L^3 / c^2 (short) or 12 mu R^3 L / c^2 (long)
  mjtNum clearance;    // c [m]
  mjtNum ratio_max;    // epsilon_t = 1 - h_t / c, the transition clamp
  mjtNum couette;      // 2 pi mu R^3 L / c [N m s]
} clFilm;

// read and validate the attributes film, viscosity, bearing_length, transition_thickness;
// film "none" (or absent) leaves model = FILM_NONE; 0 on failure (a warning says why)
int cl_configure_film(const mjModel* m, int instance, mjtNum clearance, mjtNum journal_radius,
                      clFilm* f);

// the coefficients a_r, b_r, a_t, b_t, g_t at epsilon = ratio (film.film_terms)
void cl_film_terms(int model, mjtNum ratio, mjtNum k[5]);

// For r' = A - (1/h) G r over a step h with G = h W K (W symmetric positive semi-definite, K
// symmetric positive definite, both 2x2, row-major), the matrices Phi = phi1(-G) and
// Psi = psi(G) (cl_exponential_means applied to G), so that the mean of r over the step is
// Phi r0 + h Psi A. Computed through the symmetric Gs = h L' W L (K = L L'), whose eigenvalues
// are G's: f(G) = L^-T f(Gs) L'.
void cl_exponential_means2(mjtNum h, const mjtNum W[4], const mjtNum K[4], mjtNum Phi[4],
                           mjtNum Psi[4]);

#endif  // CLEARANCE_FILM_H_
