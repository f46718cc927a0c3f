/*
 * Device driver plugins that are wrong on purpose, for tests/device/plugin_device_test.cpp: one
 * source, one shared object per TEST_DRIVER_* case (tests/CMakeLists.txt). Plain C99 against
 * the public header alone, which also checks that the header is C99.
 */
#include "hapsim/device_driver.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct hapsim_driver_device {
  int unused;
};

static hapsim_driver_device* test_open(const char* config, char* error, size_t error_bytes) {
  (void)config;
#if defined(TEST_DRIVER_OPEN_FAILS)
  /* Two lines on purpose: hapsim must still report one. */
  snprintf(error, error_bytes, "no device on /dev/fake0\nplug it in");
  return NULL;
#else
  (void)error;
  (void)error_bytes;
  return calloc(1, sizeof(hapsim_driver_device));
#endif
}

#if !defined(TEST_DRIVER_NULL_READ)
static int test_read_state(hapsim_driver_device* d, double t, hapsim_driver_state* s) {
  (void)d;
#if defined(TEST_DRIVER_NO_SAMPLE)
  (void)t;
  (void)s;
  return 1;
#elif defined(TEST_DRIVER_FROZEN)
  (void)t;
  s->timestamp_s = 42.0; /* a driver whose servo thread died: the same sample forever */
  s->orientation_wxyz[0] = 1.0;
  return 0;
#else
  s->timestamp_s = t;
  s->orientation_wxyz[0] = 1.0;
  return 0;
#endif
}
#endif

static int test_write_command(hapsim_driver_device* d, const hapsim_driver_command* c) {
  (void)d;
  (void)c;
  return 0;
}

static void test_rated_limits(hapsim_driver_device* d, hapsim_driver_limits* l) {
  (void)d;
  l->max_force_n = 1.0;
  l->workspace_min_m[0] = -0.1;
  l->workspace_max_m[0] = 0.1;
#if defined(TEST_DRIVER_BAD_LIMITS)
  l->max_stiffness_n_per_m = NAN;
#endif
}

static void test_health(hapsim_driver_device* d, hapsim_driver_health* h) {
  (void)d;
  h->code = HAPSIM_DRIVER_HEALTH_OK;
}

static void test_close(hapsim_driver_device* d) {
  free(d);
}

static const hapsim_device_driver kTable = {
#if defined(TEST_DRIVER_WRONG_ABI)
    HAPSIM_DEVICE_DRIVER_ABI_VERSION + 6,
#else
    HAPSIM_DEVICE_DRIVER_ABI_VERSION,
#endif
    "test-driver",
    test_open,
#if defined(TEST_DRIVER_NULL_READ)
    NULL,
#else
    test_read_state,
#endif
    test_write_command,
    test_rated_limits,
    test_health,
    test_close,
};

#if defined(TEST_DRIVER_NO_ENTRY)
/* Built against an imagined older header: the entry point hapsim looks for is absent. */
HAPSIM_DRIVER_EXPORT const hapsim_device_driver* hapsim_device_driver_v0(void);
HAPSIM_DRIVER_EXPORT const hapsim_device_driver* hapsim_device_driver_v0(void) {
  return &kTable;
}
#else
HAPSIM_DRIVER_EXPORT const hapsim_device_driver* hapsim_device_driver_v1(void) {
  return &kTable;
}
#endif
