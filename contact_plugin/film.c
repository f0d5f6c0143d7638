// The oil film of a lubricated journal bearing (see film.h).

#include "film.h"

#include <math.h>
#include <string.h>

#include "plugin_util.h"

static const mjtNum kPi = 3.14159265358979323846;

int cl_configure_film(const mjModel* m, int instance, mjtNum clearance, mjtNum journal_radius,
                      clFilm* f) {
  f->model = FILM_NONE;
  const char* text = cl_attr(m, instance, "film");
  if (!text || !strcmp(text, "none")) {
    return 1;
  }
  if (!strcmp(text, "short")) {
    f->model = FILM_SHORT;
  } else if (!strcmp(text, "long")) {
    f->model = FILM_LONG;
  } else {
    mju_warning("%s instance %d: attribute 'film' = '%s', expected none, short or long",
                cl_plugin_name(m, instance), instance, text);
    return 0;
  }
  mjtNum mu, length, ht;
  if (!cl_read_number(m, instance, "viscosity", NULL, &mu) ||
      !cl_check(m, mu > 0, instance, "viscosity", mu, "> 0 [Pa s]") ||
      !cl_read_number(m, instance, "bearing_length", NULL, &length) ||
      !cl_check(m, length > 0, instance, "bearing_length", length, "> 0 [m]") ||
      !cl_read_number(m, instance, "transition_thickness", NULL, &ht) ||
      !cl_check(m, ht > 0 && ht < clearance, instance, "transition_thickness", ht,
                "in (0, clearance) [m]")) {
    return 0;
  }
  mjtNum c = clearance, r = journal_radius;
  f->scale = f->model == FILM_SHORT ? mu * r * length * length * length / (c * c)
                                    : 12.0 * mu * r * r * r * length / (c * c);
  f->clearance = c;
  f->ratio_max = 1.0 - ht / c;
  f->couette = 2.0 * kPi * mu * r * r * r * length / c;
  return 1;
}

void cl_film_terms(int model, mjtNum ratio, mjtNum k[5]) {
  mjtNum e2 = ratio * ratio;
  mjtNum s = 1.0 - e2;
  mjtNum rs = sqrt(s);
  if (model == FILM_SHORT) {
    k[0] = e2 / (s * s);
    k[1] = kPi * (1.0 + 2.0 * e2) / (2.0 * s * s * rs);
    k[2] = kPi * ratio / (4.0 * s * rs);
    k[3] = 2.0 * ratio / (s * s);
    k[4] = kPi / (2.0 * s * rs);
  } else {
    mjtNum q = 2.0 + e2;
    k[0] = e2 / (q * s);
    k[1] = (kPi / 2.0 - 8.0 / (kPi * q)) / (s * rs);
    k[2] = kPi * ratio / (2.0 * q * rs);
    k[3] = 2.0 * ratio / (q * s);
    k[4] = kPi / (q * rs);
  }
}

// C = A B for 2x2 row-major matrices
static void mul2(mjtNum C[4], const mjtNum A[4], const mjtNum B[4]) {
  mjtNum c0 = A[0] * B[0] + A[1] * B[2], c1 = A[0] * B[1] + A[1] * B[3];
  mjtNum c2 = A[2] * B[0] + A[3] * B[2], c3 = A[2] * B[1] + A[3] * B[3];
  C[0] = c0;
  C[1] = c1;
  C[2] = c2;
  C[3] = c3;
}

void cl_exponential_means2(mjtNum h, const mjtNum W[4], const mjtNum K[4], mjtNum Phi[4],
                           mjtNum Psi[4]) {
  // K = L L', L lower triangular
  mjtNum l11 = sqrt(K[0]);
  mjtNum l21 = K[2] / l11;
  mjtNum l22 = sqrt(mju_max(K[3] - l21 * l21, mjMINVAL));
  mjtNum L[4] = {l11, 0.0, l21, l22}, Lt[4] = {l11, l21, 0.0, l22};
  mjtNum Linvt[4] = {1.0 / l11, -l21 / (l11 * l22), 0.0, 1.0 / l22};  // L^-T
  // Gs = h L' W L, symmetric
  mjtNum T[4], Gs[4];
  mul2(T, Lt, W);
  mul2(Gs, T, L);
  mjtNum a = h * Gs[0], b = 0.5 * h * (Gs[1] + Gs[2]), dd = h * Gs[3];
  // eigenvalues and vectors in closed form: Q = [[cs, -sn], [sn, cs]]
  mjtNum theta = 0.5 * atan2(2.0 * b, a - dd);
  mjtNum cs = cos(theta), sn = sin(theta);
  mjtNum g1 = a * cs * cs + 2.0 * b * sn * cs + dd * sn * sn;
  mjtNum g2 = a * sn * sn - 2.0 * b * sn * cs + dd * cs * cs;
  mjtNum p1, q1, p2, q2;
  cl_exponential_means(mju_max(g1, 0.0), &p1, &q1);
  cl_exponential_means(mju_max(g2, 0.0), &p2, &q2);
  mjtNum f[2][4];
  mjtNum vals[2][2] = {{p1, p2}, {q1, q2}};
  for (int k = 0; k < 2; k++) {
    mjtNum x = vals[k][0], y = vals[k][1];
    // Q diag(x, y) Q'
    mjtNum S[4] = {x * cs * cs + y * sn * sn, (x - y) * sn * cs, (x - y) * sn * cs,
                   x * sn * sn + y * cs * cs};
    mul2(T, Linvt, S);
    mul2(f[k], T, Lt);
  }
  memcpy(Phi, f[0], sizeof(mjtNum) * 4);
  memcpy(Psi, f[1], sizeof(mjtNum) * 4);
}
