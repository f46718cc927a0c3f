#include "bench/link_sweep.h"

#include "hapsim/force/local_contact_model.h"
#include "hapsim/net/device_state_codec.h"
#include "hapsim/net/device_state_gate.h"
#include "hapsim/net/link_shim.h"
#include "hapsim/net/local_model_codec.h"
#include "hapsim/net/local_model_gate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>

namespace hapsim::bench {

// The net layer's pieces the sweep runs, as a device host and serve run them.
using net::DeviceStateGate;
using net::DeviceStateSample;
using net::encode_device_state;
using net::encode_local_model;
using net::ForceMode;
using net::LinkShim;
using net::LinkShimCounts;
using net::LinkShimOptions;
using net::LocalModelGate;
using net::SampleVerdict;

namespace {

// Penetration runs along world +x; the surface's outward normal is −x.
const Vec3 kIn = Vec3::UnitX();

constexpr std::uint16_t kDeviceId = 1;
constexpr std::uint64_t kSceneHash = 0x5157'EE9Eu;
// In flight at most (delay + jitter) / dt samples each way: 150 at 100 ms with 50 ms of jitter.
constexpr std::size_t kLinkCapacity = 512;
constexpr double kForceZero_n = 0.01;
constexpr double kTail_s = 1.0;
// stable: ripple below this share of the analytic hold, and at most this much net work fed in.
constexpr double kStableRippleShare = 0.1;
constexpr double kStableHoldWork_j = 1e-3;

// The newest raw force the simulation computed, with its sequence (the device keeps the newest).
struct RawForce {
  double force_n = 0.0;
  std::uint64_t sequence = 0;
};

double tissue_depth_m(const OneDofPlant& p, double force_n) {
  return p.tissue_y0_m * std::log1p(std::max(force_n, 0.0) / p.tissue_a_n);
}

double tissue_stiffness_n_per_m(const OneDofPlant& p, double depth_m) {
  return p.tissue_a_n / p.tissue_y0_m * std::exp(depth_m / p.tissue_y0_m);
}

// Bisection on an increasing g with g(lo) ≤ 0 ≤ g(hi).
template <typename G>
double bisect(G g, double lo, double hi) {
  for (int i = 0; i < 100 && hi - lo > 1e-15 * std::max(1.0, std::abs(hi)); ++i) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) > 0.0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

// The device position at which the tissue contact carries `force_n` (tissue settled under it).
double tissue_position_m(const OneDofPlant& p, double force_n) {
  return tissue_depth_m(p, force_n) + force_n / p.contact_stiffness_n_per_m;
}

// The contact's stiffness the model carries: the whole contact's, or the contact spring's alone.
double model_stiffness_n_per_m(const LinkCase& c, double tissue_depth) {
  const OneDofPlant& p = c.plant;
  if (c.environment == SweepEnvironment::kWall) {
    return p.wall_stiffness_n_per_m;
  }
  if (c.model_stiffness == ModelStiffness::kContactOnly) {
    return p.contact_stiffness_n_per_m;
  }
  return series_stiffness_n_per_m(p.contact_stiffness_n_per_m,
                                  tissue_stiffness_n_per_m(p, tissue_depth));
}

// How the tissue stiffens about x0: the settled force's rise from x0 at a few depths around it
// (down to the surface, which pushes nothing), added to f0 (force/local_contact_model.h).
void fill_tissue_profile(const OneDofPlant& p, double x0_m, double f0_n, LocalContactModel& m) {
  constexpr std::array<double, 8> kOffsets_m{-0.016, -0.008, -0.004, 0.0,
                                             0.004,  0.008,  0.016,  0.032};
  const double at_x0_n = quasi_static_force_n(p, SweepEnvironment::kTissue, x0_m);
  int count = 0;
  const auto add = [&](double depth_m) {
    const auto k = static_cast<std::size_t>(count++);
    m.profile_depth_m[k] = depth_m;
    m.profile_push_n[k] =
        f0_n + quasi_static_force_n(p, SweepEnvironment::kTissue, x0_m + depth_m) - at_x0_n;
  };
  if (x0_m > 0.0 && x0_m + kOffsets_m.front() < 0.0) {
    add(-x0_m);  // the surface
  }
  for (const double offset_m : kOffsets_m) {
    if (x0_m + offset_m > 0.0 && offset_m > (count > 0 ? m.profile_depth_m[count - 1] : -1.0) &&
        count < LocalContactModel::kMaxProfilePoints) {
      add(offset_m);
    }
  }
  m.profile_count = count >= 2 ? count : 0;
}

// The simulation's local model for a device state (SPEC §8): its tissue sits where the force the
// device rendered put it, and f0 is corrected for it (force/local_contact_model.h).
LocalContactModel make_model(const LinkCase& c, const DeviceStateSample& s,
                             std::uint64_t sequence) {
  const OneDofPlant& p = c.plant;
  const double x_m = s.input.p_world.dot(kIn);
  const double rendered_n = s.rendered.force_world_n.dot(-kIn);
  const bool wall = c.environment == SweepEnvironment::kWall;
  const double depth_m = wall ? 0.0 : tissue_depth_m(p, rendered_n);
  const double contact_k = wall ? p.wall_stiffness_n_per_m : p.contact_stiffness_n_per_m;
  const double k_n_per_m = model_stiffness_n_per_m(c, depth_m);
  const double f0_n = tissue_coupled_force_n(rendered_n, x_m - depth_m, contact_k, k_n_per_m);
  LocalContactModel m;
  m.x0_world_m = s.input.p_world;
  m.v0_world_m_per_s = s.v_world_m_per_s;
  m.f0_world_n = -f0_n * kIn;
  m.stiffness_n_per_m = k_n_per_m * kIn * kIn.transpose();
  m.damping_n_s_per_m = p.contact_damping_n_s_per_m * kIn * kIn.transpose();
  m.normal_world = -kIn;
  m.validity_radius_m = p.validity_radius_m;
  if (!wall && c.tissue_profile) {
    fill_tissue_profile(p, x_m, f0_n, m);
  }
  m.sim_time_s = s.input.time_s;
  m.sequence = sequence;
  m.device_sequence = s.sequence;
  m.valid = true;
  return m;
}

// One simulated session: device, links, simulation. Heap-allocated by the caller (the links hold
// a few hundred kilobytes of slots).
class Session {
 public:
  explicit Session(const LinkCase& c)
      : c_(c),
        hand_(hand_model(c.hand)),
        up_(link_options(c, 2 * c.seed + 1)),
        down_(link_options(c, 2 * c.seed + 2)),
        raw_down_(link_options(c, 2 * c.seed + 2)),
        renderer_(LocalModelRenderOptions{c.plant.max_force_n, c.blend_s, c.stale_after_s, c.fade_s,
                                          c.reengage_s}),
        observer_(c.observer),
        model_gate_(kDeviceId, kSceneHash, 1),
        state_gate_(kDeviceId, kSceneHash) {}

  LinkRun run() {
    const OneDofPlant& p = c_.plant;
    LinkRun r;
    // An outage adds its length and 1.5 s to settle again before the last second.
    r.duration_s = c_.duration_s > 0.0 ? c_.duration_s
                                       : default_duration_s(c_.delay_s, c_.jitter_s) +
                                             (c_.outage_start_s >= 0.0 ? c_.outage_s + 1.5 : 0.0);
    const auto steps = static_cast<std::int64_t>(std::llround(r.duration_s / p.dt_s));
    const std::int64_t tail_from =
        std::max<std::int64_t>(0, steps - std::llround(kTail_s / p.dt_s));
    double x_m = p.start_m;
    double v_m_per_s = 0.0;
    double work_j = 0.0;  // by the rendered force on the device
    double work_at_tail_j = 0.0;
    double sum = 0.0;
    double sum_sq = 0.0;
    double last_model_s = -1.0;
    for (std::int64_t k = 0; k < steps; ++k) {
      const double now_s = static_cast<double>(k) * p.dt_s;
      // Device side: apply what arrived, render from its own fresh state.
      if (c_.mode == ForceMode::kRaw) {
        raw_down_.deliver(now_s, [&](const RawForce& f) {
          // Newest by sequence, like a gate: a late force is older news than the one held.
          if (has_raw_ && f.sequence <= raw_.sequence) {
            ++r.refused_out_of_order;
            return;
          }
          raw_ = f;
          has_raw_ = true;
          ++r.models_accepted;
          last_model_s = now_s;
        });
      } else {
        down_.deliver(now_s, [&](const hapsim_msg_LocalModel& message) {
          LocalContactModel model;
          const SampleVerdict verdict = model_gate_.admit(message, device_sequence_, model);
          if (verdict == SampleVerdict::kAccepted) {
            renderer_.receive(model, now_s);
            ++r.models_accepted;
            last_model_s = now_s;
          } else if (verdict == SampleVerdict::kOutOfOrder) {
            ++r.refused_out_of_order;
          } else {
            ++r.refused_other;
          }
        });
      }
      const Vec3 x_world_m = x_m * kIn;
      const Vec3 v_world_m_per_s = v_m_per_s * kIn;
      Vec3 force_world_n = Vec3::Zero();
      if (c_.mode == ForceMode::kRaw) {
        force_world_n = -std::clamp(raw_.force_n, 0.0, p.max_force_n) * kIn;
      } else {
        force_world_n = renderer_.render(x_world_m, v_world_m_per_s, now_s);
        if (c_.passivity_observer) {
          force_world_n = observer_.filter(force_world_n, v_world_m_per_s, p.dt_s);
        }
      }
      const double force_n = force_world_n.dot(-kIn);  // pushing out of the surface

      if (k >= tail_from) {
        if (k == tail_from) {
          work_at_tail_j = work_j;
        }
        sum += force_n;
        sum_sq += force_n * force_n;
      }
      r.peak_force_n = std::max(r.peak_force_n, std::abs(force_n));
      // The outage's zero: the first cycle from which the force stays below 0.01 N to the
      // outage's end (an oscillation passing through zero does not count).
      if (c_.outage_start_s >= 0.0 && now_s >= c_.outage_start_s - 1e-9 &&
          now_s < c_.outage_start_s + c_.outage_s - 1e-9) {
        if (std::abs(force_n) >= kForceZero_n) {
          r.outage_force_zero_s = -1.0;
          r.outage_force_zero_after_last_model_s = -1.0;
        } else if (r.outage_force_zero_s < 0.0) {
          r.outage_force_zero_s = now_s - c_.outage_start_s;
          r.outage_force_zero_after_last_model_s = now_s - last_model_s;
        }
      }

      DeviceStateSample state;
      state.device_id = kDeviceId;
      state.sequence = device_sequence_;
      state.input.time_s = now_s;
      state.input.p_world = x_world_m;
      state.v_world_m_per_s = v_world_m_per_s;
      state.rendered.force_world_n = force_world_n;
      up_.send(encode_device_state(state, kSceneHash), now_s);

      // The device moves under the hand and the rendered force (semi-implicit Euler); the work
      // the force does over the step is exact for it.
      const double hand_n = hand_.stiffness_n_per_m * (hand_target_m(now_s) - x_m) -
                            hand_.damping_n_s_per_m * v_m_per_s;
      v_m_per_s += (hand_n - force_n) / p.device_mass_kg * p.dt_s;
      const double next_x_m = x_m + v_m_per_s * p.dt_s;
      work_j -= force_n * (next_x_m - x_m);
      x_m = next_x_m;
      ++device_sequence_;
      // Energy generated: what the force gave the device plus what the ideal environment
      // holding that force would still hold (header).
      r.energy_generated_j = std::max(
          r.energy_generated_j, work_j + stored_energy_at_force_j(p, c_.environment, force_n));
      r.energy_out_j = std::max(r.energy_out_j, work_j);

      // Simulation side: answer every device state that arrived, newest only.
      up_.deliver(now_s, [&](const hapsim_msg_DeviceState& message) {
        DeviceStateSample s;
        const SampleVerdict verdict = state_gate_.admit(message, s);
        if (verdict == SampleVerdict::kOutOfOrder) {
          ++r.refused_out_of_order;
          return;
        }
        if (verdict != SampleVerdict::kAccepted) {
          ++r.refused_other;
          return;
        }
        if (c_.mode == ForceMode::kRaw) {
          const double sx_m = s.input.p_world.dot(kIn);
          const double f_n = quasi_static_force_n(p, c_.environment, sx_m);
          raw_down_.send(
              {f_n > 0.0 ? f_n + p.contact_damping_n_s_per_m * s.v_world_m_per_s.dot(kIn) : 0.0,
               ++model_sequence_},
              now_s);
        } else {
          down_.send(
              encode_local_model(make_model(c_, s, ++model_sequence_), {kDeviceId, 0}, kSceneHash),
              now_s);
        }
      });
    }
    const double n = static_cast<double>(steps - tail_from);
    r.steady_force_n = sum / n;
    r.hold_ripple_rms_n =
        std::sqrt(std::max(0.0, sum_sq / n - r.steady_force_n * r.steady_force_n));
    r.hold_work_j = work_j - work_at_tail_j;
    const double hold_n = analytic_hold_force_n(p, c_.environment, c_.hand);
    r.stable = r.hold_ripple_rms_n < kStableRippleShare * hold_n &&
               r.hold_work_j <= kStableHoldWork_j && std::isfinite(r.steady_force_n);
    r.observer = observer_.counts();
    for (const LinkShimCounts* counts : {&up_.counts(), &down_.counts(), &raw_down_.counts()}) {
      r.lost += counts->lost_random + counts->lost_burst + counts->lost_outage + counts->lost_full;
      r.reordered += counts->reordered;
    }
    return r;
  }

 private:
  // Where the hand pulls the device to at `now_s`: the start, then (minimum jerk) the target.
  [[nodiscard]] double hand_target_m(double now_s) const {
    const double from_m = c_.plant.start_m;
    if (now_s < c_.approach_start_s) {
      return from_m;
    }
    if (!(c_.approach_s > 0.0) || now_s >= c_.approach_start_s + c_.approach_s) {
      return hand_.target_m;
    }
    const double s = (now_s - c_.approach_start_s) / c_.approach_s;
    return from_m + (hand_.target_m - from_m) * s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
  }

  static LinkShimOptions link_options(const LinkCase& c, std::uint64_t seed) {
    LinkShimOptions o;
    o.delay_s = c.delay_s;
    o.jitter_s = c.jitter_s;
    o.loss = c.loss;
    o.outage_start_s = c.outage_start_s;
    o.outage_s = c.outage_s;
    o.seed = seed;
    return o;
  }

  LinkCase c_;
  HandModel hand_;
  LinkShim<hapsim_msg_DeviceState, kLinkCapacity> up_;
  LinkShim<hapsim_msg_LocalModel, kLinkCapacity> down_;
  LinkShim<RawForce, kLinkCapacity> raw_down_;
  LocalModelRenderer renderer_;
  PassivityObserver observer_;
  LocalModelGate model_gate_;
  DeviceStateGate state_gate_;
  RawForce raw_;
  bool has_raw_ = false;
  std::uint64_t device_sequence_ = 0;
  std::uint64_t model_sequence_ = 0;
};

}  // namespace

const char* environment_name(SweepEnvironment environment) noexcept {
  return environment == SweepEnvironment::kTissue ? "tissue" : "wall";
}

const char* hand_name(SweepHand hand) noexcept {
  return hand == SweepHand::kRelaxed ? "relaxed" : "stiff";
}

HandModel hand_model(SweepHand hand) noexcept {
  if (hand == SweepHand::kStiff) {
    return {1200.0, 6.0, 0.02};
  }
  return {300.0, 2.0, 0.02};
}

double default_duration_s(double delay_s, double jitter_s) noexcept {
  return std::max(4.5, 2.5 + 20.0 * (2.0 * delay_s + jitter_s));
}

double quasi_static_force_n(const OneDofPlant& p, SweepEnvironment environment,
                            double x_m) noexcept {
  if (!(x_m > 0.0)) {
    return 0.0;
  }
  if (environment == SweepEnvironment::kWall) {
    return p.wall_stiffness_n_per_m * x_m;
  }
  return bisect([&](double f) { return tissue_position_m(p, f) - x_m; }, 0.0,
                p.contact_stiffness_n_per_m * x_m);
}

double stored_energy_at_force_j(const OneDofPlant& p, SweepEnvironment environment,
                                double force_n) noexcept {
  if (!(force_n > 0.0)) {
    return 0.0;
  }
  if (environment == SweepEnvironment::kWall) {
    return 0.5 * force_n * force_n / p.wall_stiffness_n_per_m;
  }
  // The contact spring's F²/(2·k_c) plus the tissue's ∫a·(exp(s/y0) − 1)ds = y0·F − a·y.
  return 0.5 * force_n * force_n / p.contact_stiffness_n_per_m + p.tissue_y0_m * force_n -
         p.tissue_a_n * tissue_depth_m(p, force_n);
}

double analytic_hold_force_n(const OneDofPlant& p, SweepEnvironment environment,
                             SweepHand hand) noexcept {
  const HandModel h = hand_model(hand);
  if (environment == SweepEnvironment::kWall) {
    // Two springs in series between the hand's target and the wall.
    return h.stiffness_n_per_m * p.wall_stiffness_n_per_m /
           (h.stiffness_n_per_m + p.wall_stiffness_n_per_m) * h.target_m;
  }
  return bisect(
      [&](double f) { return f - h.stiffness_n_per_m * (h.target_m - tissue_position_m(p, f)); },
      0.0, h.stiffness_n_per_m * h.target_m);
}

LinkRun run_link_case(const LinkCase& link_case) {
  return std::make_unique<Session>(link_case)->run();
}

LinkSweepOptions quick_link_sweep_options() {
  LinkSweepOptions o;
  o.delays_ms = {0, 20, 100};
  o.losses = {0.0, 0.3};
  return o;
}

std::vector<LinkSweepRow> run_link_sweep(const LinkSweepOptions& options) {
  std::vector<LinkCase> cases;
  const auto make_case = [&](ForceMode mode, SweepEnvironment environment, SweepHand hand,
                             int delay_ms, double loss) {
    LinkCase c;
    c.mode = mode;
    c.environment = environment;
    c.hand = hand;
    c.delay_s = 1e-3 * delay_ms;
    c.jitter_s = options.jitter_fraction * c.delay_s;
    c.loss = loss;
    c.approach_s = options.approach_s;
    c.blend_s = options.blend_s;
    c.passivity_observer = options.passivity_observer;
    c.seed = options.seed;
    return c;
  };
  for (const ForceMode mode : options.modes) {
    for (const SweepEnvironment environment : options.environments) {
      for (const SweepHand hand : options.hands) {
        for (const int delay_ms : options.delays_ms) {
          for (const double loss : options.losses) {
            cases.push_back(make_case(mode, environment, hand, delay_ms, loss));
          }
        }
      }
    }
  }
  if (options.outage_s > 0.0) {
    for (const ForceMode mode : options.modes) {
      for (const SweepEnvironment environment : options.environments) {
        for (const SweepHand hand : options.hands) {
          LinkCase c = make_case(mode, environment, hand, options.outage_delay_ms, 0.0);
          c.outage_start_s = options.outage_start_s;
          c.outage_s = options.outage_s;
          cases.push_back(c);
        }
      }
    }
  }

  std::vector<LinkSweepRow> rows;
  rows.reserve(cases.size());
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const LinkCase& c = cases[i];
    report_progress(options.progress,
                    std::string(to_string(c.mode)) + " " + environment_name(c.environment) + " " +
                        hand_name(c.hand),
                    static_cast<double>(i) / static_cast<double>(cases.size()));
    LinkSweepRow row;
    row.link_case = c;
    row.run = run_link_case(c);
    row.analytic_force_n = analytic_hold_force_n(c.plant, c.environment, c.hand);
    rows.push_back(row);
  }
  report_progress(options.progress, "done", 1.0);

  // The local model's reference: its own zero-delay, loss-free run (from the grid when there,
  // else run once per mode, environment and hand).
  std::vector<LinkSweepRow> references;
  const auto reference_for = [&](const LinkCase& c) {
    const auto same = [&](const LinkSweepRow& other) {
      const LinkCase& o = other.link_case;
      return o.mode == c.mode && o.environment == c.environment && o.hand == c.hand &&
             o.delay_s == 0.0 && o.loss == 0.0 && !other.is_outage();
    };
    if (const auto in_grid = std::find_if(rows.begin(), rows.end(), same); in_grid != rows.end()) {
      return in_grid->run.steady_force_n;
    }
    if (const auto run = std::find_if(references.begin(), references.end(), same);
        run != references.end()) {
      return run->run.steady_force_n;
    }
    LinkSweepRow reference;
    reference.link_case = make_case(c.mode, c.environment, c.hand, 0, 0.0);
    reference.run = run_link_case(reference.link_case);
    references.push_back(reference);
    return reference.run.steady_force_n;
  };
  for (LinkSweepRow& row : rows) {
    const LinkCase& c = row.link_case;
    row.reference_force_n = c.mode == ForceMode::kRaw ? row.analytic_force_n : reference_for(c);
    row.steady_force_error =
        row.reference_force_n > 0.0
            ? (row.run.steady_force_n - row.reference_force_n) / row.reference_force_n
            : 0.0;
  }
  return rows;
}

}  // namespace hapsim::bench
