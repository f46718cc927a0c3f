/*
 * An example hapsim device driver plugin (docs/devices.md), built in-tree from the public header
 * hapsim/device_driver.h alone: a simulated stylus, held by a simulated hand, whose tool runs
 * round a horizontal circle and presses down once per press period, and whose gripper closes
 * during each press.
 *
 * The hand holding it is a spring: the tool sits where the path puts it plus F / k_hand, so the
 * force hapsim tells the device to render shows up in the next position it reports (and a
 * finger force opens that finger by F / k_finger). That makes the plugin a closed loop that
 * tests can check exactly, and a template for a real driver: parse the config in open(), keep
 * read_state/health/write_command non-blocking, convert to SI in the device frame.
 *
 * Config (key=value, separated by spaces or commas; every key optional):
 *   radius_m=0.03 period_s=4 center_x_m=0 center_y_m=0 center_z_m=0 press_depth_m=0.01
 *   press_period_s=1 hand_stiffness_n_per_m=500 fingers=2 finger_stiffness_n_per_rad=2
 * and, to exercise hapsim's guards: fail_after_s=T (health FAILED from host time T on),
 * nan_after_s=T (a NaN position from host time T on).
 *
 *   hapsim device --device plugin:build/release/examples/device_plugin/hapsim_example_device.so
 */
#include "hapsim/device_driver.h"

#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EXAMPLE_PI 3.14159265358979323846
#define EXAMPLE_MAX_FORCE_N 5.0
#define EXAMPLE_MAX_FINGER_FORCE_N 2.0

struct hapsim_driver_device {
  double radius_m;
  double period_s;
  double center_m[3];
  double press_depth_m;
  double press_period_s;
  double hand_stiffness_n_per_m;
  int fingers;
  double finger_stiffness_n_per_rad;
  double fail_after_s; /* < 0: never */
  double nan_after_s;  /* < 0: never */
  /* Written by write_command (haptic or supervisor thread), read by read_state (haptic thread):
     atomics, so the two never race. A vector mixing two commands' components is harmless here. */
  _Atomic double force_n[3];
  _Atomic double finger_force_n[HAPSIM_DRIVER_MAX_FINGERS];
  _Atomic double last_host_time_s;
};

static double clamp(double v, double lo, double hi) {
  return v < lo ? lo : (v > hi ? hi : v);
}

/* Sets *out from text "value"; 0 on success. */
static int parse_number(const char* value, double* out) {
  char* end = NULL;
  const double v = strtod(value, &end);
  if (end == value || *end != '\0' || !isfinite(v)) {
    return 1;
  }
  *out = v;
  return 0;
}

static int apply_option(hapsim_driver_device* d, const char* key, const char* value, char* error,
                        size_t error_bytes) {
  struct {
    const char* key;
    double* target;
  } numbers[] = {
      {"radius_m", &d->radius_m},
      {"period_s", &d->period_s},
      {"center_x_m", &d->center_m[0]},
      {"center_y_m", &d->center_m[1]},
      {"center_z_m", &d->center_m[2]},
      {"press_depth_m", &d->press_depth_m},
      {"press_period_s", &d->press_period_s},
      {"hand_stiffness_n_per_m", &d->hand_stiffness_n_per_m},
      {"finger_stiffness_n_per_rad", &d->finger_stiffness_n_per_rad},
      {"fail_after_s", &d->fail_after_s},
      {"nan_after_s", &d->nan_after_s},
  };
  size_t i;
  for (i = 0; i < sizeof numbers / sizeof numbers[0]; ++i) {
    if (strcmp(key, numbers[i].key) == 0) {
      if (parse_number(value, numbers[i].target) != 0) {
        snprintf(error, error_bytes, "%s='%s' is not a finite number", key, value);
        return 1;
      }
      return 0;
    }
  }
  if (strcmp(key, "fingers") == 0) {
    double n = 0.0;
    if (parse_number(value, &n) != 0 || n != floor(n) || n < 0 || n > HAPSIM_DRIVER_MAX_FINGERS) {
      snprintf(error, error_bytes, "fingers='%s' is not a whole number from 0 to %d", value,
               HAPSIM_DRIVER_MAX_FINGERS);
      return 1;
    }
    d->fingers = (int)n;
    return 0;
  }
  snprintf(error, error_bytes,
           "unknown key '%s' (known: radius_m, period_s, center_x_m, center_y_m, center_z_m, "
           "press_depth_m, press_period_s, hand_stiffness_n_per_m, fingers, "
           "finger_stiffness_n_per_rad, fail_after_s, nan_after_s)",
           key);
  return 1;
}

static hapsim_driver_device* example_open(const char* config, char* error, size_t error_bytes) {
  hapsim_driver_device* d = calloc(1, sizeof *d);
  char text[512];
  char* token;
  int i;
  if (d == NULL) {
    snprintf(error, error_bytes, "out of memory");
    return NULL;
  }
  d->radius_m = 0.03;
  d->period_s = 4.0;
  d->press_depth_m = 0.01;
  d->press_period_s = 1.0;
  d->hand_stiffness_n_per_m = 500.0;
  d->fingers = 2;
  d->finger_stiffness_n_per_rad = 2.0;
  d->fail_after_s = -1.0;
  d->nan_after_s = -1.0;
  for (i = 0; i < 3; ++i) {
    atomic_init(&d->force_n[i], 0.0);
  }
  for (i = 0; i < HAPSIM_DRIVER_MAX_FINGERS; ++i) {
    atomic_init(&d->finger_force_n[i], 0.0);
  }
  atomic_init(&d->last_host_time_s, 0.0);

  if (strlen(config) >= sizeof text) {
    snprintf(error, error_bytes, "config longer than %u characters", (unsigned)sizeof text - 1);
    free(d);
    return NULL;
  }
  strcpy(text, config);
  /* Tokens are separated by spaces, tabs or commas (strtok_r is POSIX, not C). */
  for (token = text; *token != '\0';) {
    char* end = token + strcspn(token, " ,\t");
    char* eq;
    const int last = *end == '\0';
    *end = '\0';
    if (*token != '\0') {
      eq = strchr(token, '=');
      if (eq == NULL) {
        snprintf(error, error_bytes, "'%s' is not key=value", token);
        free(d);
        return NULL;
      }
      *eq = '\0';
      if (apply_option(d, token, eq + 1, error, error_bytes) != 0) {
        free(d);
        return NULL;
      }
    }
    token = last ? end : end + 1;
  }
  if (d->radius_m < 0.0 || d->period_s <= 0.0 || d->press_period_s <= 0.0 ||
      d->press_depth_m < 0.0 || d->hand_stiffness_n_per_m <= 0.0 ||
      d->finger_stiffness_n_per_rad <= 0.0) {
    snprintf(error, error_bytes,
             "radius_m and press_depth_m must be >= 0; period_s, press_period_s and the "
             "stiffnesses > 0");
    free(d);
    return NULL;
  }
  return d;
}

/* haptic path: arithmetic only. */
static int example_read_state(hapsim_driver_device* d, double t, hapsim_driver_state* s) {
  const double theta = 2.0 * EXAMPLE_PI * t / d->period_s;
  const double omega = 2.0 * EXAMPLE_PI / d->period_s;
  const double phase = 2.0 * EXAMPLE_PI * t / d->press_period_s;
  const double press = 0.5 * (1.0 - cos(phase)); /* 0 -> 1 -> 0 once per press period */
  int i;
  atomic_store_explicit(&d->last_host_time_s, t, memory_order_relaxed);

  s->timestamp_s = t;
  s->position_m[0] = d->center_m[0] + d->radius_m * cos(theta);
  s->position_m[1] = d->center_m[1] + d->radius_m * sin(theta);
  s->position_m[2] = d->center_m[2] - d->press_depth_m * press;
  for (i = 0; i < 3; ++i) {
    s->position_m[i] +=
        atomic_load_explicit(&d->force_n[i], memory_order_relaxed) / d->hand_stiffness_n_per_m;
  }
  s->velocity_m_per_s[0] = -d->radius_m * omega * sin(theta);
  s->velocity_m_per_s[1] = d->radius_m * omega * cos(theta);
  s->velocity_m_per_s[2] =
      -d->press_depth_m * 0.5 * sin(phase) * 2.0 * EXAMPLE_PI / d->press_period_s;
  /* The stylus points along the circle's tangent: a yaw of theta. */
  s->orientation_wxyz[0] = cos(0.5 * theta);
  s->orientation_wxyz[1] = 0.0;
  s->orientation_wxyz[2] = 0.0;
  s->orientation_wxyz[3] = sin(0.5 * theta);
  s->finger_count = d->fingers;
  for (i = 0; i < d->fingers; ++i) {
    const double f = atomic_load_explicit(&d->finger_force_n[i], memory_order_relaxed);
    s->finger_rad[i] = clamp(0.6 * press - f / d->finger_stiffness_n_per_rad, 0.0, 1.5);
  }
  s->buttons = press > 0.5 ? 1u : 0u;
  if (d->nan_after_s >= 0.0 && t >= d->nan_after_s) {
    s->position_m[0] = NAN;
  }
  return 0;
}

/* haptic path: clamps again (a device never amplifies) and stores. */
static int example_write_command(hapsim_driver_device* d, const hapsim_driver_command* c) {
  int i;
  for (i = 0; i < 3; ++i) {
    const double f = isfinite(c->force_n[i]) ? c->force_n[i] : 0.0;
    atomic_store_explicit(&d->force_n[i], clamp(f, -EXAMPLE_MAX_FORCE_N, EXAMPLE_MAX_FORCE_N),
                          memory_order_relaxed);
  }
  for (i = 0; i < HAPSIM_DRIVER_MAX_FINGERS; ++i) {
    const double f =
        i < c->finger_count && isfinite(c->finger_force_n[i]) ? c->finger_force_n[i] : 0.0;
    atomic_store_explicit(&d->finger_force_n[i], clamp(f, 0.0, EXAMPLE_MAX_FINGER_FORCE_N),
                          memory_order_relaxed);
  }
  return 0;
}

static void example_rated_limits(hapsim_driver_device* d, hapsim_driver_limits* l) {
  const double reach = d->radius_m + 0.05;
  int i;
  snprintf(l->model_name, sizeof l->model_name,
           "hapsim example: circle-and-press simulated stylus");
  l->max_force_n = EXAMPLE_MAX_FORCE_N;
  l->max_continuous_force_n = EXAMPLE_MAX_FORCE_N;
  l->max_stiffness_n_per_m = 1000.0;
  l->max_damping_n_s_per_m = 5.0;
  for (i = 0; i < 3; ++i) {
    l->workspace_min_m[i] = d->center_m[i] - reach;
    l->workspace_max_m[i] = d->center_m[i] + reach;
  }
  l->finger_count = d->fingers;
  l->max_finger_force_n = d->fingers > 0 ? EXAMPLE_MAX_FINGER_FORCE_N : 0.0;
  l->max_joint_torque_nm = 0.0;
  l->max_force_rate_n_per_s = 0.0;
}

static void example_health(hapsim_driver_device* d, hapsim_driver_health* h) {
  const double t = atomic_load_explicit(&d->last_host_time_s, memory_order_relaxed);
  if (d->fail_after_s >= 0.0 && t >= d->fail_after_s) {
    h->code = HAPSIM_DRIVER_HEALTH_FAILED;
    /* a fixed text: snprintf may allocate for some formats, and this runs at 1 kHz */
    strncpy(h->reason, "simulated fault (fail_after_s)", sizeof h->reason - 1);
    return;
  }
  h->code = HAPSIM_DRIVER_HEALTH_OK;
}

static void example_close(hapsim_driver_device* d) {
  free(d);
}

static const hapsim_device_driver kExampleDriver = {
    HAPSIM_DEVICE_DRIVER_ABI_VERSION,
    "example-circle-press",
    example_open,
    example_read_state,
    example_write_command,
    example_rated_limits,
    example_health,
    example_close,
};

HAPSIM_DRIVER_EXPORT const hapsim_device_driver* hapsim_device_driver_v1(void) {
  return &kExampleDriver;
}
