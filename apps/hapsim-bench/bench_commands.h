// The subcommands of `hapsim-bench` (`hapsim bench` runs it): a program of its own because the
// collision cases compare against CGAL, FCL and Embree, test and benchmark oracles that the
// `hapsim` users install must not link (cmake/HapsimOracles.cmake).
#pragma once

#include <CLI/CLI.hpp>

namespace hapsim::app {

/// collision, step, passivity, snapshot, contact, fem, soak and network, on `bench`.
void add_bench_subcommands(CLI::App& bench);
/// `hapsim bench snapshot` (snapshot_bench.cpp).
void add_snapshot_bench(CLI::App& bench);

}  // namespace hapsim::app
