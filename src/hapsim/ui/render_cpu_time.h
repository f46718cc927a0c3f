// CPU time the drawing costs, per thread kind, for the viewer's figures: on a shared machine
// (a build beside it) frames per second measure the load as much as the viewer, while the CPU
// seconds the viewer's own thread and Mesa's rasteriser threads (llvmpipe-N) spent per frame do
// not. Linux only (/proc/self/task); elsewhere both read zero.
#pragma once

namespace hapsim {

struct RenderCpuTime {
  /// The calling thread's CPU time (the viewer's: scene update, draw calls, panels, swap), s.
  double viewer_thread_s = 0.0;
  /// Summed over the process's threads named llvmpipe-* (Mesa's software rasteriser), s; clock
  /// ticks, so 10 ms resolution per thread.
  double rasteriser_s = 0.0;
};

/// Now, since the threads started.
[[nodiscard]] RenderCpuTime render_cpu_time_now();

}  // namespace hapsim
