#include "hapsim/core/leak_check.h"

#include "hapsim/core/sanitizer_build.h"

#include <dlfcn.h>
#include <link.h>

#include <cstddef>

namespace hapsim {

void keep_libraries_mapped_for_leak_check() {
#if HAPSIM_LEAK_SANITIZER
  dl_iterate_phdr(
      [](dl_phdr_info* info, std::size_t /*size*/, void* /*data*/) -> int {
        if (info->dlpi_name != nullptr && info->dlpi_name[0] != '\0') {
          // RTLD_NOLOAD: only what is mapped already; RTLD_NODELETE: later dlclose()s keep it.
          void* handle = dlopen(info->dlpi_name, RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE);
          if (handle != nullptr) {
            dlclose(handle);  // our reference only; the library stays mapped
          }
        }
        return 0;
      },
      nullptr);
#endif
}

bool built_with_leak_checks() {
  return kBuiltWithLeakSanitizer;
}

}  // namespace hapsim
