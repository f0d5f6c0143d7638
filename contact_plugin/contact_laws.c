// The normal contact laws of the compiled contacts (see contact_laws.h).

#include "contact_laws.h"

#include <math.h>
#include <string.h>

#include "plugin_util.h"

static const char* const kLawNames[LAW_COUNT] = {
  "hertz", "lankarani_nikravesh", "hunt_crossley", "flores", "gonthier", "hu_guo", "impact",
  "johnson", "radzimovsky", "goldsmith", "dubowsky_freudenstein", "esdu_78035", "liu",
  "pereira", "persson"
};

static int logarithmic(int law) {
  return law >= LAW_JOHNSON && law <= LAW_ESDU_78035;
}

static int cylindrical(int law) {
  return law >= LAW_JOHNSON && law <= LAW_PERSSON;
}

static int read_law(const mjModel* m, int instance, int* law) {
  const char* text = cl_attr(m, instance, "law");
  if (!text) {
    mju_warning("%s instance %d: attribute 'law' is required", cl_plugin_name(m, instance),
                instance);
    return 0;
  }
  for (int i = 0; i < LAW_COUNT; i++) {
    if (!strcmp(text, kLawNames[i])) {
      *law = i;
      return 1;
    }
  }
  mjtNum code;
  if (cl_parse_number(text, &code) && code == floor(code) && code >= 0 && code < LAW_COUNT) {
    *law = (int)code;
    return 1;
  }
  mju_warning("%s instance %d: attribute 'law' = '%s', expected one of hertz, "
              "lankarani_nikravesh, hunt_crossley, flores, gonthier, hu_guo, impact, johnson, "
              "radzimovsky, goldsmith, dubowsky_freudenstein, esdu_78035, liu, pereira, persson "
              "or 0..14",
              cl_plugin_name(m, instance), instance, text);
  return 0;
}

mjtNum cl_hysteresis(int law, mjtNum e) {
  switch (law) {
    case LAW_LN:       return 3.0 * (1.0 - e * e) / 4.0;
    case LAW_HC:       return 1.5 * (1.0 - e);
    case LAW_FLORES:   return 8.0 * (1.0 - e) / (5.0 * e);
    case LAW_GONTHIER: return (1.0 - e * e) / e;
    case LAW_HU_GUO:   return 3.0 * (1.0 - e) / (2.0 * e);
    default:           return 0.0;
  }
}

// the cylindrical laws' constants: the logarithmic laws' k, F0, beta and delta*, the others'
// stiffness (and PEREIRA's exponent) and delta* (inf for LIU and PEREIRA), c for LIU and PERSSON
static int configure_cylinder(const mjModel* m, int instance, clLaw* lw) {
  static const mjtNum kZero = 0.0, kInf = INFINITY;
  lw->compliance = lw->reference_force = lw->offset = 0.0;
  if (!cl_read_number(m, instance, "clearance", NULL, &lw->clearance) ||
      !cl_check(m, lw->clearance > 0, instance, "clearance", lw->clearance, "> 0 [m]")) {
    return 0;
  }
  lw->max_penetration = INFINITY;
  const char* dmax = cl_attr(m, instance, "max_penetration");
  if (dmax && strcmp(dmax, "inf") && !cl_read_number(m, instance, "max_penetration", &kInf,
                                                     &lw->max_penetration)) {
    return 0;
  }
  if (!cl_check(m, lw->max_penetration > 0, instance, "max_penetration", lw->max_penetration,
                "> 0 [m]")) {
    return 0;
  }
  if (logarithmic(lw->law)) {
    return cl_read_number(m, instance, "compliance", NULL, &lw->compliance) &&
           cl_check(m, lw->compliance > 0, instance, "compliance", lw->compliance, "> 0 [m/N]") &&
           cl_read_number(m, instance, "reference_force", NULL, &lw->reference_force) &&
           cl_check(m, lw->reference_force > 0, instance, "reference_force", lw->reference_force,
                    "> 0 [N]") &&
           cl_read_number(m, instance, "offset", &kZero, &lw->offset);
  }
  return 1;
}

int cl_configure_law(const mjModel* m, int instance, clLaw* lw) {
  static const mjtNum kExponent = 1.5;
  if (!read_law(m, instance, &lw->law)) {
    return 0;
  }
  if (cylindrical(lw->law)) {
    // stiffness: S of LIU and PERSSON, K of PEREIRA; unused (1) by the logarithmic laws
    static const mjtNum kOne = 1.0;
    if (!configure_cylinder(m, instance, lw) ||
        !cl_read_number(m, instance, "stiffness", logarithmic(lw->law) ? &kOne : NULL,
                        &lw->stiffness) ||
        !cl_check(m, lw->stiffness > 0, instance, "stiffness", lw->stiffness, "> 0") ||
        !cl_read_number(m, instance, "exponent", &kExponent, &lw->exponent) ||
        !cl_read_number(m, instance, "restitution", NULL, &lw->restitution) ||
        !cl_check(m, lw->restitution >= 0 && lw->restitution <= 1, instance, "restitution",
                  lw->restitution, "in [0, 1]")) {
      return 0;
    }
    lw->chi = cl_hysteresis(LAW_LN, lw->restitution);  // Lankarani-Nikravesh's hysteresis
    lw->c_max = 0.0;
    lw->d_max = 1.0;
    return 1;
  }
  lw->max_penetration = INFINITY;
  if (!cl_read_number(m, instance, "stiffness", NULL, &lw->stiffness) ||
      !cl_check(m, lw->stiffness > 0, instance, "stiffness", lw->stiffness, "> 0 [N/m^n]") ||
      !cl_read_number(m, instance, "exponent", &kExponent, &lw->exponent) ||
      !cl_check(m, lw->exponent > 0, instance, "exponent", lw->exponent, "> 0")) {
    return 0;
  }

  lw->restitution = 1.0;
  lw->chi = 0.0;
  if (lw->law != LAW_HERTZ && lw->law != LAW_IMPACT) {
    if (!cl_read_number(m, instance, "restitution", NULL, &lw->restitution)) {
      return 0;
    }
    mjtNum e = lw->restitution;
    if (lw->law == LAW_LN || lw->law == LAW_HC) {
      if (!cl_check(m, e >= 0 && e <= 1, instance, "restitution", e, "in [0, 1]")) return 0;
    } else {
      if (!cl_check(m, e > 0 && e <= 1, instance, "restitution", e, "in (0, 1]")) return 0;
    }
    lw->chi = cl_hysteresis(lw->law, e);
  }

  lw->c_max = 0.0;
  lw->d_max = 1.0;
  if (lw->law == LAW_IMPACT) {
    if (!cl_read_number(m, instance, "c_max", NULL, &lw->c_max) ||
        !cl_check(m, lw->c_max >= 0, instance, "c_max", lw->c_max, ">= 0 [N s/m]") ||
        !cl_read_number(m, instance, "d_max", NULL, &lw->d_max) ||
        !cl_check(m, lw->d_max > 0, instance, "d_max", lw->d_max, "> 0 [m]")) {
      return 0;
    }
  }
  return 1;
}

// F with delta = k F (beta + ln(F0 / F)) on the rising branch, to rounding: Newton's method in
// u = ln(F / F0) (cylindrical_laws.solve_logarithmic, operation by operation)
static mjtNum newton_step(mjtNum u, mjtNum offset, mjtNum ln_d) {
  mjtNum w = offset - u;
  return (u + log(w) - ln_d) * w / (w - 1.0);
}

static mjtNum solve_logarithmic(mjtNum compliance, mjtNum reference_force, mjtNum offset,
                                mjtNum delta) {
  static const mjtNum kTol = 4.0 * 2.220446049250313e-16;  // 4 ulps of max(1, |u|)
  mjtNum ln_d = log(delta / (compliance * reference_force));
  if (ln_d >= offset - 1.0) {
    return reference_force * exp(offset - 1.0);
  }
  mjtNum u = ln_d - log(offset - ln_d);
  u -= newton_step(u, offset, ln_d);
  for (int i = 0; i < 100; i++) {
    mjtNum step = newton_step(u, offset, ln_d);
    if (!(step < 0.0)) break;
    u -= step;
    if (-step <= kTol * mju_max(1.0, mju_abs(u))) break;
  }
  return reference_force * exp(u);
}

mjtNum cl_elastic_force(const clLaw* lw, mjtNum delta) {
  if (delta <= 0.0) {
    return 0.0;
  }
  if (delta > lw->max_penetration) {
    return INFINITY;
  }
  if (logarithmic(lw->law)) {
    return solve_logarithmic(lw->compliance, lw->reference_force, lw->offset, delta);
  }
  if (lw->law == LAW_LIU) {
    return lw->stiffness * delta * sqrt(delta / (2.0 * (lw->clearance + delta)));
  }
  if (lw->law == LAW_PERSSON) {
    mjtNum s = delta / (2.0 * lw->clearance + delta);
    mjtNum den = 2.0 - log1p(s) - 2.0 * s * s;
    return den > 0.0 ? lw->stiffness * s * (1.0 + s) / den : INFINITY;
  }
  return lw->stiffness * pow(delta, lw->exponent);  // the point laws and PEREIRA
}

mjtNum cl_normal_force(const clLaw* lw, mjtNum delta, mjtNum fel, mjtNum rate, mjtNum vin) {
  if (delta <= 0) {
    return 0;
  }
  mjtNum f;
  if (lw->law == LAW_HERTZ) {
    return fel;
  } else if (lw->law == LAW_IMPACT) {
    mjtNum z = mju_clip(delta / lw->d_max, 0.0, 1.0);
    f = fel + lw->c_max * (z * z * (3.0 - 2.0 * z)) * rate;
  } else {
    f = fel * (1.0 + lw->chi * (rate / vin));
  }
  return f > 0 ? f : 0.0;
}

static const mjtNum kGaussX[24] = {
  -0.9951872199970213, -0.9747285559713095, -0.9382745520027328,
  -0.8864155270044011, -0.820001985973903, -0.7401241915785544,
  -0.6480936519369755, -0.5454214713888396, -0.4337935076260451,
  -0.3150426796961634, -0.1911188674736163, -0.06405689286260563,
  0.06405689286260563, 0.1911188674736163, 0.3150426796961634,
  0.4337935076260451, 0.5454214713888396, 0.6480936519369755,
  0.7401241915785544, 0.820001985973903, 0.8864155270044011,
  0.9382745520027328, 0.9747285559713095, 0.9951872199970213
};
static const mjtNum kGaussW[24] = {
  0.01234122979998869, 0.02853138862893356, 0.04427743881741941,
  0.05929858491543636, 0.07334648141108016, 0.0861901615319532,
  0.09761865210411393, 0.10744427011596556, 0.11550566805372552,
  0.1216704729278033, 0.12583745634682825, 0.12793819534675202,
  0.12793819534675202, 0.12583745634682825, 0.1216704729278033,
  0.11550566805372552, 0.10744427011596556, 0.09761865210411393,
  0.0861901615319532, 0.07334648141108016, 0.05929858491543636,
  0.04427743881741941, 0.02853138862893356, 0.01234122979998869
};  // numpy.polynomial.legendre.leggauss(24)

mjtNum cl_elastic_energy(const clLaw* lw, mjtNum delta, mjtNum fel) {
  if (delta <= 0.0) {
    return 0.0;
  }
  if (logarithmic(lw->law)) {
    return fel * delta / 2.0 - lw->compliance * fel * fel / 4.0;
  }
  mjtNum c = lw->clearance;
  if (lw->law == LAW_LIU) {
    mjtNum root = sqrt(delta * (c + delta)) * (2.0 * delta - 3.0 * c) / 4.0;
    return lw->stiffness / sqrt(2.0) * (root + 0.75 * c * c * asinh(sqrt(delta / c)));
  }
  if (lw->law == LAW_PERSSON) {
    if (!isfinite(fel)) {
      return INFINITY;
    }
    mjtNum sum = 0.0;
    for (int i = 0; i < 24; i++) {
      sum += kGaussW[i] * cl_elastic_force(lw, 0.5 * delta * (kGaussX[i] + 1.0));
    }
    return 0.5 * delta * sum;
  }
  return fel * delta / (lw->exponent + 1.0);  // the point laws and PEREIRA
}

mjtNum cl_law_damping(const clLaw* lw, mjtNum delta, mjtNum fel, mjtNum vin) {
  if (lw->law == LAW_HERTZ) {
    return 0.0;
  } else if (lw->law == LAW_IMPACT) {
    mjtNum z = mju_clip(delta / lw->d_max, 0.0, 1.0);
    return lw->c_max * (z * z * (3.0 - 2.0 * z));
  }
  return fel * lw->chi / vin;
}
