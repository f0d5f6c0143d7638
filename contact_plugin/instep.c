// What the compiled contacts' in-step treatment shares (see instep.h).

#include "instep.h"

#include <math.h>
#include <stdlib.h>

#include "plugin_util.h"

int cl_configure_friction(const mjModel* m, int instance, clFriction* fr) {
  static const mjtNum kZero = 0.0, kV0 = 1e-4, kV1 = 1e-3;
  return cl_read_number(m, instance, "friction", &kZero, &fr->mu) &&
         cl_check(m, fr->mu >= 0, instance, "friction", fr->mu, ">= 0") &&
         cl_read_number(m, instance, "v0", &kV0, &fr->v0) &&
         cl_read_number(m, instance, "v1", &kV1, &fr->v1) &&
         cl_check(m, fr->v0 >= 0, instance, "v0", fr->v0, ">= 0 [m/s]") &&
         cl_check(m, fr->v1 > fr->v0, instance, "v1", fr->v1, "> v0 [m/s]");
}

// Ambrosio's coefficient c_d(v) sign(v): F_t = -mu F_n ramp(v), the operations of laws._friction
static mjtNum friction_ramp(const clFriction* fr, mjtNum vt) {
  mjtNum cd = mju_clip((mju_abs(vt) - fr->v0) / (fr->v1 - fr->v0), 0.0, 1.0);
  mjtNum sign = vt > 0 ? 1.0 : (vt < 0 ? -1.0 : 0.0);
  return cd * sign;
}

mjtNum cl_friction_force(const clFriction* fr, mjtNum fn, mjtNum vt) {
  if (fr->mu == 0) {
    return 0.0;
  }
  return -fr->mu * friction_ramp(fr, vt) * fn + 0.0;
}

mjtNum cl_implicit_sliding_velocity(const clFriction* fr, mjtNum v_free, mjtNum kk) {
  mjtNum a = mju_abs(v_free), sign = v_free >= 0 ? 1.0 : -1.0;
  if (a <= fr->v0 || kk <= 0) {
    return v_free;
  }
  if (a - kk >= fr->v1) {
    return sign * (a - kk);  // gross sliding through the step
  }
  mjtNum slope = kk / (fr->v1 - fr->v0);
  return sign * (a + slope * fr->v0) / (1.0 + slope);  // inside the ramp
}

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

int cl_equality_init(const mjModel* m, clEquality* eq) {
  int nv = m->nv;
  eq->max = equality_rows_max(m);
  eq->rows = NULL;
  if (eq->max <= 0) {
    return 1;
  }
  int k = eq->max;
  eq->rows = (mjtNum*)calloc((size_t)(2 * k * nv + k * k + 2 * k), sizeof(mjtNum));
  if (!eq->rows) {
    return 0;
  }
  eq->y = eq->rows + k * nv;
  eq->a = eq->y + k * nv;
  eq->z = eq->a + k * k;
  return 1;
}

void cl_equality_free(clEquality* eq) {
  free(eq->rows);
  eq->rows = NULL;
}

int cl_equality_factor(const mjModel* m, mjData* d, clEquality* eq) {
  int nv = m->nv, k = 0;
  if (eq->max <= 0) {
    return 0;
  }
  for (int r = 0; r < d->nefc; r++) {
    if (d->efc_type[r] != mjCNSTR_EQUALITY) continue;
    if (k == eq->max) return 0;  // more rows than the model declares: keep the free response
    mjtNum* row = eq->rows + k * nv;
    if (mj_isSparse(m)) {
      mju_zero(row, nv);
      int adr = d->efc_J_rowadr[r];
      for (int j = 0; j < d->efc_J_rownnz[r]; j++) {
        row[d->efc_J_colind[adr + j]] = d->efc_J[adr + j];
      }
    } else {
      mju_copy(row, d->efc_J + r * nv, nv);
    }
    eq->z[k] = d->efc_R[r];  // R, held here until the factor is built
    k++;
  }
  if (k == 0) {
    return 0;
  }
  mj_solveM(m, d, eq->y, eq->rows, k);
  for (int i = 0; i < k; i++) {
    for (int j = 0; j <= i; j++) {
      mjtNum a = mju_dot(eq->rows + i * nv, eq->y + j * nv, nv);
      eq->a[i * k + j] = a;
      eq->a[j * k + i] = a;
    }
    eq->a[i * k + i] += eq->z[i];
  }
  return mju_cholFactor(eq->a, k, mjMINVAL) < k ? 0 : k;  // singular: keep the free response
}

void cl_constrain(const clEquality* eq, int k, int nv, mjtNum* u) {
  mjtNum* b = eq->z;
  mjtNum* z = eq->z + eq->max;
  for (int i = 0; i < k; i++) {
    b[i] = mju_dot(eq->rows + i * nv, u, nv);
  }
  mju_cholSolve(z, eq->a, b, k);
  for (int i = 0; i < k; i++) {
    mju_addToScl(u, eq->y + i * nv, -z[i], nv);
  }
}

void cl_exponential_means_diag(int k, mjtNum h, const mjtNum* W, const mjtNum* damping,
                               mjtNum* Phi, mjtNum* Psi) {
  mjtNum a[16], v[16], sq[4];
  for (int i = 0; i < k; i++) {
    sq[i] = sqrt(damping[i]);
  }
  for (int i = 0; i < k; i++) {
    for (int j = 0; j < k; j++) {
      a[i * k + j] = h * sq[i] * 0.5 * (W[i * k + j] + W[j * k + i]) * sq[j];
      v[i * k + j] = i == j ? 1.0 : 0.0;
    }
  }
  // cyclic Jacobi: a -> diag, v the eigenvectors (columns)
  for (int sweep = 0; sweep < 50; sweep++) {
    mjtNum off = 0, diag = 0;
    for (int i = 0; i < k; i++) {
      diag += a[i * k + i] * a[i * k + i];
      for (int j = i + 1; j < k; j++) off += a[i * k + j] * a[i * k + j];
    }
    if (off <= 1e-30 * diag || off == 0) break;
    for (int p = 0; p < k; p++) {
      for (int q = p + 1; q < k; q++) {
        mjtNum apq = a[p * k + q];
        if (apq == 0) continue;
        mjtNum theta = 0.5 * atan2(2.0 * apq, a[q * k + q] - a[p * k + p]);
        mjtNum cs = cos(theta), sn = sin(theta);
        for (int r = 0; r < k; r++) {  // a = J' a J, J the rotation in (p, q)
          mjtNum arp = a[r * k + p], arq = a[r * k + q];
          a[r * k + p] = cs * arp - sn * arq;
          a[r * k + q] = sn * arp + cs * arq;
        }
        for (int r = 0; r < k; r++) {
          mjtNum apr = a[p * k + r], aqr = a[q * k + r];
          a[p * k + r] = cs * apr - sn * aqr;
          a[q * k + r] = sn * apr + cs * aqr;
        }
        for (int r = 0; r < k; r++) {
          mjtNum vrp = v[r * k + p], vrq = v[r * k + q];
          v[r * k + p] = cs * vrp - sn * vrq;
          v[r * k + q] = sn * vrp + cs * vrq;
        }
      }
    }
  }
  mjtNum fphi[4], fpsi[4];
  for (int i = 0; i < k; i++) {
    cl_exponential_means(mju_max(a[i * k + i], 0.0), fphi + i, fpsi + i);
  }
  for (int i = 0; i < k; i++) {
    for (int j = 0; j < k; j++) {
      mjtNum p = 0, q = 0;
      for (int e = 0; e < k; e++) {
        p += v[i * k + e] * fphi[e] * v[j * k + e];
        q += v[i * k + e] * fpsi[e] * v[j * k + e];
      }
      Phi[i * k + j] = p / sq[i] * sq[j];
      Psi[i * k + j] = q / sq[i] * sq[j];
    }
  }
}
