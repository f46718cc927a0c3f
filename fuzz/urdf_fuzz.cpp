// Fuzz target: bytes as a URDF (parse_urdf_chain: our text checks, then urdfdom/TinyXML, then the
// chain). Mesh paths resolve against a folder that does not exist; boxes, spheres and cylinders
// are built. Checks: a chain comes back whose forward kinematics at zero is finite, or
// hapsim::Error; nothing else escapes, nothing crashes (deep XML, bad UTF-8) or hangs (a joint
// whose parent is its child).
#include "file_fuzz_support.h"
#include "hapsim/kinematics/urdf_chain.h"

#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hapsim::fuzz::expect_value_or_error([&] {
    const hapsim::SerialChain chain = hapsim::parse_urdf_chain(
        hapsim::fuzz::as_text(data, size), "fuzz.urdf", "/nonexistent/hapsim-fuzz");
    const std::vector<double> q(static_cast<std::size_t>(chain.dof()), 0.0);
    HAPSIM_FUZZ_CHECK(chain.forward(q).matrix().allFinite(), "the tip pose at zero is finite");
  });
  return 0;
}
