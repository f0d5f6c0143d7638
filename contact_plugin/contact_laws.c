// The normal contact laws of the compiled contacts (see contact_laws.h).

#include "contact_laws.h"

#include <math.h>
#include <string.h>

#include "plugin_util.h"

static const char* const kLawNames[LAW_COUNT] = {
  "hertz", "lankarani_nikravesh", "hunt_crossley", "flores", "gonthier", "hu_guo", "impact"
};

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
              "lankarani_nikravesh, hunt_crossley, flores, gonthier, hu_guo, impact or 0..6",
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

int cl_configure_law(const mjModel* m, int instance, clLaw* lw) {
  static const mjtNum kExponent = 1.5;
  if (!read_law(m, instance, &lw->law) ||
      !cl_read_number(m, instance, "stiffness", NULL, &lw->stiffness) ||
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

mjtNum cl_normal_force(const clLaw* lw, mjtNum delta, mjtNum rate, mjtNum vin, mjtNum* fel) {
  *fel = 0;
  if (delta <= 0) {
    return 0;
  }
  *fel = lw->stiffness * pow(delta, lw->exponent);
  mjtNum f;
  if (lw->law == LAW_HERTZ) {
    return *fel;
  } else if (lw->law == LAW_IMPACT) {
    mjtNum z = mju_clip(delta / lw->d_max, 0.0, 1.0);
    f = *fel + lw->c_max * (z * z * (3.0 - 2.0 * z)) * rate;
  } else {
    f = *fel * (1.0 + lw->chi * (rate / vin));
  }
  return f > 0 ? f : 0.0;
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
