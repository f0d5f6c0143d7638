// What the engine plugins of this library share (see plugin_util.h).

#include "plugin_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

const char* cl_plugin_name(const mjModel* m, int instance) {
  const mjpPlugin* p = mjp_getPluginAtSlot(m->plugin[instance]);
  return p && p->name ? p->name : "clearance plugin";
}

const char* cl_attr(const mjModel* m, int instance, const char* name) {
  const char* value = mj_getPluginConfig(m, instance, name);
  if (!value) {
    return NULL;
  }
  const char* p = value;
  while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r') {
    p++;
  }
  return *p ? value : NULL;
}

int cl_parse_number(const char* text, mjtNum* out) {
  char* end;
  double v = strtod(text, &end);
  if (end == text) {
    return 0;
  }
  while (*end == ' ' || *end == '\t' || *end == '\n' || *end == '\r') {
    end++;
  }
  if (*end || !isfinite(v)) {
    return 0;
  }
  *out = v;
  return 1;
}

int cl_read_number(const mjModel* m, int instance, const char* name, const mjtNum* fallback,
                   mjtNum* out) {
  const char* text = cl_attr(m, instance, name);
  if (!text) {
    if (fallback) {
      *out = *fallback;
      return 1;
    }
    mju_warning("%s instance %d: attribute '%s' is required", cl_plugin_name(m, instance),
                instance, name);
    return 0;
  }
  if (!cl_parse_number(text, out)) {
    mju_warning("%s instance %d: attribute '%s' must be a finite number, got '%s'",
                cl_plugin_name(m, instance), instance, name, text);
    return 0;
  }
  return 1;
}

int cl_check(const mjModel* m, int ok, int instance, const char* name, mjtNum value,
             const char* expected) {
  if (!ok) {
    mju_warning("%s instance %d: attribute '%s' = %g, expected %s", cl_plugin_name(m, instance),
                instance, name, value, expected);
  }
  return ok;
}

int cl_read_site(const mjModel* m, int instance, const char* name, int* site) {
  const char* text = cl_attr(m, instance, name);
  if (!text) {
    mju_warning("%s instance %d: attribute '%s' (a site name) is required",
                cl_plugin_name(m, instance), instance, name);
    return 0;
  }
  *site = mj_name2id(m, mjOBJ_SITE, text);
  if (*site < 0) {
    mju_warning("%s instance %d: attribute '%s': no site named '%s'", cl_plugin_name(m, instance),
                instance, name, text);
    return 0;
  }
  return 1;
}

int cl_semi_implicit(const mjModel* m) {
  return m->opt.integrator != mjINT_RK4;
}

int cl_one_step_after(mjtNum t, mjtNum t0, mjtNum h) {
  return mju_abs(t - (t0 + h)) <= 1e-9 * h;
}

int cl_is_last_step(const mjModel* m, const mjData* d, mjtNum have, mjtNum sample_time) {
  return have != 0 && cl_one_step_after(d->time, sample_time, m->opt.timestep);
}

int cl_is_recent(const mjModel* m, const mjData* d, mjtNum have, mjtNum sample_time) {
  mjtNum age = d->time - sample_time;
  return have != 0 && age > 0 && age <= 2 * m->opt.timestep * (1 + 1e-9);
}

int cl_cache_slot(const void* cache, size_t stride, int n, mjtNum time, int* next) {
  const char* base = (const char*)cache;
  for (int i = 0; i < n; i++) {
    const clEvalHead* e = (const clEvalHead*)(base + i * stride);
    if (e->valid && e->time == time) return i;
  }
  for (int i = 0; i < n; i++) {
    if (!((const clEvalHead*)(base + i * stride))->valid) return i;
  }
  int slot = *next;
  *next = (*next + 1) % n;
  return slot;
}

const void* cl_cache_step_start(const void* cache, size_t stride, int n, mjtNum time, mjtNum h) {
  const char* base = (const char*)cache;
  for (int i = 0; i < n; i++) {
    const clEvalHead* e = (const clEvalHead*)(base + i * stride);
    if (e->valid && cl_one_step_after(time, e->time, h)) return e;
  }
  return NULL;
}

int* cl_instance_sensors(const mjModel* m, int instance, int* n) {
  *n = 0;
  for (int i = 0; i < m->nsensor; i++) {
    if (m->sensor_type[i] == mjSENS_PLUGIN && m->sensor_plugin[i] == instance) {
      (*n)++;
    }
  }
  int* adr = (int*)malloc(sizeof(int) * (*n > 0 ? *n : 1));
  if (!adr) {
    return NULL;
  }
  int k = 0;
  for (int i = 0; i < m->nsensor; i++) {
    if (m->sensor_type[i] == mjSENS_PLUGIN && m->sensor_plugin[i] == instance) {
      adr[k++] = m->sensor_adr[i];
    }
  }
  return adr;
}

void cl_exponential_means(mjtNum g, mjtNum* phi1, mjtNum* psi) {
  if (g < 1e-3) {  // series: the next terms are g^4 / 120 and g^4 / 720 (< 1e-14 here)
    *phi1 = 1.0 - g / 2.0 + g * g / 6.0 - g * g * g / 24.0;
    *psi = 0.5 - g / 6.0 + g * g / 24.0 - g * g * g / 120.0;
  } else {
    mjtNum em1 = expm1(-g);
    *phi1 = -em1 / g;
    *psi = (g + em1) / (g * g);
  }
}
