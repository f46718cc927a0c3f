// Text that came from a file (a recording's header, a key of a JSON file) and is echoed in a
// message: control characters are escaped, so no terminal escape sequence a crafted file carries
// reaches the screen, and long text is cut so a message stays one line.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace hapsim {

/// `text` with every C0/C1 control character (ESC, CR, LF, BEL, DEL, U+0080..U+009F) and every
/// byte that is not part of valid UTF-8 written as \xNN (a backslash as \\), cut after
/// `max_bytes` input bytes with "..." added. Printable ASCII and valid UTF-8 pass unchanged.
[[nodiscard]] std::string printable_text(std::string_view text, std::size_t max_bytes = 200);

}  // namespace hapsim
