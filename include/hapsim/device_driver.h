/*
 * hapsim device driver plugin ABI (docs/devices.md).
 *
 * A device driver is a shared object that exports ONE function, hapsim_device_driver_v1(),
 * returning a constant table of function pointers. `hapsim device --device plugin:PATH.so` loads
 * it with dlopen(RTLD_NOW | RTLD_LOCAL), checks the table and wraps it as a hapsim::Device.
 *
 * This header is the whole contract: plain C99, no hapsim or C++ header, so a driver wrapping a
 * vendor SDK (OpenHaptics, Force Dimension DHD, libnifalcon, ...) builds with any C or C++
 * compiler against this file alone.
 *
 * Units and frames. SI everywhere: metres, newtons, seconds, radians, N·m. Positions, velocities
 * and forces are in the DEVICE's own right-handed frame (the scene places the device in the
 * world); a driver converts from its SDK's units (OpenHaptics reports millimetres) here.
 * Forces are what the device applies to the user's hand: tool force along the frame's axes,
 * finger forces push only (>= 0).
 *
 * Threads and blocking. hapsim calls
 *   - open, rated_limits, close: from an ordinary thread; they may block (open may wait for a
 *     device to calibrate), never concurrently with any other call on the same device;
 *   - read_state, health, write_command: from the 1 kHz haptic thread. They MUST NOT block,
 *     sleep, allocate (malloc), wait on a lock another thread holds for long, or do I/O that can
 *     wait. A driver whose SDK runs its own servo loop hands its newest sample over without
 *     waiting (a lock-free buffer, or the SDK's own non-blocking getter); a driver that talks
 *     to the hardware itself keeps that I/O on its own thread. write_command may also be called
 *     by hapsim's supervisor thread while a stalled haptic cycle is inside read_state (to ramp
 *     the force to zero), never two write_command calls at once.
 *
 * Safety. The command hapsim writes is already clamped to the driver's rated limits and never
 * contains NaN; a driver may clamp again but never amplifies. A state with a non-finite value is
 * taken as a device failure: hapsim stops trusting the device (zero force) until it is reopened.
 * Before close, hapsim writes a zero command.
 *
 * Versioning. A driver sets abi_version = HAPSIM_DEVICE_DRIVER_ABI_VERSION from the header it
 * was built with; hapsim refuses a table whose version differs from its own (one error line
 * naming both). Any change to a struct or a function below changes the version.
 */
#ifndef HAPSIM_DEVICE_DRIVER_H
#define HAPSIM_DEVICE_DRIVER_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define HAPSIM_DEVICE_DRIVER_ABI_VERSION 1
/* The one symbol hapsim looks up in a driver. */
#define HAPSIM_DEVICE_DRIVER_ENTRY "hapsim_device_driver_v1"

#define HAPSIM_DRIVER_MAX_FINGERS 5
#define HAPSIM_DRIVER_MAX_JOINTS 16
/* Size of every text buffer in the structs below, NUL included. */
#define HAPSIM_DRIVER_TEXT_BYTES 128

#if defined(_WIN32)
#define HAPSIM_DRIVER_EXPORT __declspec(dllexport)
#elif defined(__GNUC__)
#define HAPSIM_DRIVER_EXPORT __attribute__((visibility("default")))
#else
#define HAPSIM_DRIVER_EXPORT
#endif

/* One opened device; the driver defines struct hapsim_driver_device as it likes. */
typedef struct hapsim_driver_device hapsim_driver_device;

/* One sample of the device, filled by read_state. hapsim zeroes it before each call. */
typedef struct hapsim_driver_state {
  /* When the driver took this sample, on its own monotonic clock (any epoch), seconds. It must
     change when a new sample arrives: hapsim reports the device stale when it stops changing. */
  double timestamp_s;
  double position_m[3];
  /* Unit quaternion w, x, y, z; 1, 0, 0, 0 for a device without orientation. */
  double orientation_wxyz[4];
  /* Tool velocity; a driver whose device does not measure it estimates it (e.g. a filtered
     difference over its own servo period). */
  double velocity_m_per_s[3];
  /* Finger flexion per finger (a glove), or a gripper's opening angle. */
  double finger_rad[HAPSIM_DRIVER_MAX_FINGERS];
  int32_t finger_count;
  int32_t joint_count;
  double joint_rad[HAPSIM_DRIVER_MAX_JOINTS];
  /* Bit 0 = primary button. */
  uint32_t buttons;
  uint32_t reserved; /* 0 */
} hapsim_driver_state;

/* What the device should render now. */
typedef struct hapsim_driver_command {
  double force_n[3];
  /* Per finger actuator, >= 0; finger_count entries used. */
  double finger_force_n[HAPSIM_DRIVER_MAX_FINGERS];
  int32_t finger_count;
  int32_t joint_count;
  double joint_torque_nm[HAPSIM_DRIVER_MAX_JOINTS];
} hapsim_driver_command;

/* Rated limits, asked once after open: what hapsim clamps every command to, and the stiffest
   spring it may render on this device. Every number finite and >= 0. */
typedef struct hapsim_driver_limits {
  char model_name[HAPSIM_DRIVER_TEXT_BYTES]; /* human-readable, NUL-terminated */
  double max_force_n;                        /* peak tool force; 0 without a tool actuator */
  double max_continuous_force_n;
  double max_stiffness_n_per_m;
  double max_damping_n_s_per_m;
  double workspace_min_m[3]; /* reachable box, device frame */
  double workspace_max_m[3];
  int32_t finger_count; /* force-actuated fingers, 0..HAPSIM_DRIVER_MAX_FINGERS */
  int32_t reserved;     /* 0 */
  double max_finger_force_n;
  double max_joint_torque_nm;
  double max_force_rate_n_per_s; /* slow (pneumatic) actuators; 0 = not rate-limited */
} hapsim_driver_limits;

enum {
  HAPSIM_DRIVER_HEALTH_OK = 0,    /* samples arrive, commands are rendered */
  HAPSIM_DRIVER_HEALTH_STALE = 1, /* connected, no fresh sample lately (may recover) */
  HAPSIM_DRIVER_HEALTH_FAILED = 2 /* link lost or device error: forces must go to zero */
};

typedef struct hapsim_driver_health {
  int32_t code;                          /* HAPSIM_DRIVER_HEALTH_* */
  char reason[HAPSIM_DRIVER_TEXT_BYTES]; /* why, unless OK; NUL-terminated */
} hapsim_driver_health;

typedef struct hapsim_device_driver {
  /* HAPSIM_DEVICE_DRIVER_ABI_VERSION of the header the driver was built with. First, so hapsim
     can read it whatever the rest of the table looks like. */
  uint32_t abi_version;
  /* Short lower-case name, e.g. "touch-openhaptics"; becomes the device profile's name. */
  const char* name;

  /* Opens the device described by `config` (driver-defined text, never NULL, may be empty).
     Returns NULL on failure after writing one line into `error` (error_bytes >= 1). May block. */
  hapsim_driver_device* (*open)(const char* config, char* error, size_t error_bytes);

  /* Newest sample into `state`. `host_time_s` is hapsim's time for this cycle (simulation time:
     a simulated device follows it; hardware ignores it and returns its newest sample). Returns 0
     when `state` holds a sample, non-zero when none is available. Haptic thread: non-blocking. */
  int (*read_state)(hapsim_driver_device* device, double host_time_s, hapsim_driver_state* state);

  /* Render `command` (already within the rated limits). Returns 0, or non-zero when the device
     did not take it (counted by hapsim; say why in health). Haptic thread: non-blocking. */
  int (*write_command)(hapsim_driver_device* device, const hapsim_driver_command* command);

  /* Rated limits into `limits` (hapsim zeroes it first). Called once, after open. */
  void (*rated_limits)(hapsim_driver_device* device, hapsim_driver_limits* limits);

  /* Health into `health` (hapsim zeroes it first). Haptic thread: non-blocking. */
  void (*health)(hapsim_driver_device* device, hapsim_driver_health* health);

  /* Stops the device and frees it. May block (joins the driver's threads). */
  void (*close)(hapsim_driver_device* device);
} hapsim_device_driver;

/* The entry point's type, for dlsym. */
typedef const hapsim_device_driver* (*hapsim_device_driver_entry_fn)(void);

/* The one function a driver exports: its table, valid until the shared object is unloaded. */
HAPSIM_DRIVER_EXPORT const hapsim_device_driver* hapsim_device_driver_v1(void);

#ifdef __cplusplus
}
#endif

#endif /* HAPSIM_DEVICE_DRIVER_H */
