// Fuzz target: bytes as the number CSVs of `hapsim query` (points, 3 columns), `fk` (joint rows,
// 6) and `ik` (poses, 7): parse_number_rows_csv (apps/hapsim/number_csv.h). The first byte picks
// the column count. Checks: every row has exactly that many finite numbers, or hapsim::Error.
#include "../apps/hapsim/number_csv.h"
#include "file_fuzz_support.h"

#include <cmath>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) {
    return 0;
  }
  static const std::size_t kColumns[] = {3, 6, 7};
  const std::size_t columns = kColumns[data[0] % 3];
  hapsim::fuzz::expect_value_or_error([&] {
    const auto rows = hapsim::app::parse_number_rows_csv(hapsim::fuzz::as_text(data + 1, size - 1),
                                                         "fuzz.csv", columns, "x,y,z", "points");
    HAPSIM_FUZZ_CHECK(!rows.empty(), "at least one row");
    for (const auto& row : rows) {
      HAPSIM_FUZZ_CHECK(row.size() == columns, "every row has the column count");
      for (double v : row) {
        HAPSIM_FUZZ_CHECK(std::isfinite(v), "every number is finite");
      }
    }
  });
  return 0;
}
