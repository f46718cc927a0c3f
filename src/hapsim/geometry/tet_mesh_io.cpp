#include "hapsim/geometry/tet_mesh_io.h"

#include "hapsim/core/atomic_file.h"
#include "hapsim/core/error.h"
#include "hapsim/core/text_file.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace hapsim {
namespace {

// Larger than any tet mesh a haptic FEM body can run (80k tets in Gmsh ASCII is ~10 MB), small
// enough that a hostile path cannot exhaust memory.
constexpr std::size_t kTetMeshMaxBytes = std::size_t{512} << 20;
// Node indices are 32-bit; a count above this is corrupt whatever the file's size.
constexpr std::int64_t kTetIoMaxCount = std::numeric_limits<std::uint32_t>::max() - 1;

std::string tet_io_lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

bool tet_io_iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && tet_io_lower(a) == tet_io_lower(b);
}

// Whitespace-separated tokens with line numbers for messages. With `hash_comments`, '#' to the end
// of the line is whitespace (TetGen).
class TetIoText {
 public:
  TetIoText(std::string_view text, std::string where, bool hash_comments = false)
      : text_(text), where_(std::move(where)), hash_comments_(hash_comments) {}

  // The next token, or nullopt at the end of the text.
  std::optional<std::string_view> try_token() {
    skip_space();
    if (pos_ >= text_.size()) {
      return std::nullopt;  // messages keep the line of the last token
    }
    token_line_ = line_;
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !is_space(text_[pos_]) &&
           !(hash_comments_ && text_[pos_] == '#')) {
      ++pos_;
    }
    return text_.substr(start, pos_ - start);
  }

  // The next token; at the end of the text, an error saying what was expected.
  std::string_view token(std::string_view expected) {
    const auto t = try_token();
    if (!t) {
      fail("unexpected end of file: expected " + std::string(expected) +
           " (the file is truncated)");
    }
    return *t;
  }

  // The next token without consuming it.
  std::optional<std::string_view> peek() {
    const std::size_t pos = pos_;
    const std::size_t line = line_;
    const std::size_t token_line = token_line_;
    const auto t = try_token();
    pos_ = pos;
    line_ = line;
    token_line_ = token_line;
    return t;
  }

  // The rest of the current line (after the last token), and moves to the next line.
  std::string_view rest_of_line() {
    const std::size_t start = pos_;
    while (pos_ < text_.size() && text_[pos_] != '\n') {
      ++pos_;
    }
    std::string_view rest = text_.substr(start, pos_ - start);
    if (pos_ < text_.size()) {
      ++pos_;
      ++line_;
    }
    while (!rest.empty() && is_space(rest.back())) {
      rest.remove_suffix(1);
    }
    while (!rest.empty() && is_space(rest.front())) {
      rest.remove_prefix(1);
    }
    return rest;
  }

  std::int64_t integer(std::string_view expected, std::int64_t lo, std::int64_t hi) {
    const std::string_view t = token(expected);
    std::int64_t value = 0;
    const char* first = t.data();
    if (!t.empty() && t.front() == '+') {
      ++first;
    }
    const auto [ptr, ec] = std::from_chars(first, t.data() + t.size(), value);
    if (ec != std::errc() || ptr != t.data() + t.size()) {
      fail("expected " + std::string(expected) + " (an integer), found '" + excerpt(t) + "'");
    }
    if (value < lo || value > hi) {
      fail(std::string(expected) + " " + std::to_string(value) + " is out of range (" +
           std::to_string(lo) + " to " + std::to_string(hi) + ")");
    }
    return value;
  }

  // A count of items that each take at least `min_bytes` of the text still to read: a count
  // larger than the rest of the file can hold is refused before anything is reserved for it.
  std::size_t count(std::string_view expected, std::size_t min_bytes) {
    const auto n = static_cast<std::size_t>(integer(expected, 0, kTetIoMaxCount));
    if (n > 0 && (n - 1) > remaining() / std::max<std::size_t>(min_bytes, 1)) {
      fail(std::string(expected) + " " + std::to_string(n) +
           " is more than the rest of the file can hold (truncated or corrupt)");
    }
    return n;
  }

  double real(std::string_view expected) {
    const std::string_view t = token(expected);
    double value = 0.0;
    const char* first = t.data();
    if (!t.empty() && t.front() == '+') {
      ++first;
    }
    const auto [ptr, ec] = std::from_chars(first, t.data() + t.size(), value);
    if (ec != std::errc() || ptr != t.data() + t.size()) {
      fail("expected " + std::string(expected) + " (a number), found '" + excerpt(t) + "'");
    }
    if (!std::isfinite(value)) {
      fail(std::string(expected) + " is not a finite number ('" + excerpt(t) + "')");
    }
    return value;
  }

  void expect(std::string_view keyword) {
    const std::string_view t = token(keyword);
    if (t != keyword) {
      fail("expected " + std::string(keyword) + ", found '" + excerpt(t) + "'");
    }
  }

  [[noreturn]] void fail(const std::string& what) const { throw Error(here(), what); }
  [[nodiscard]] std::string here() const { return where_ + ":" + std::to_string(token_line_); }
  [[nodiscard]] std::size_t line() const { return token_line_; }
  [[nodiscard]] std::size_t remaining() const { return text_.size() - pos_; }
  [[nodiscard]] const std::string& where() const { return where_; }

  // A token as quoted in a message: at most 40 printable characters.
  static std::string excerpt(std::string_view t) {
    std::string out;
    for (const char c : t.substr(0, 40)) {
      out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
    }
    return t.size() > 40 ? out + "..." : out;
  }

 private:
  static bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
  }
  void skip_space() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n') {
        ++line_;
        ++pos_;
      } else if (is_space(c)) {
        ++pos_;
      } else if (hash_comments_ && c == '#') {
        while (pos_ < text_.size() && text_[pos_] != '\n') {
          ++pos_;
        }
      } else {
        break;
      }
    }
  }

  std::string_view text_;
  std::string where_;
  bool hash_comments_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
  std::size_t token_line_ = 1;
};

// Orientation, then validation naming the file's line for a bad element. A file that lists
// every tet the other way round (its convention) is flipped silently; a file with both
// orientations keeps them, and validation refuses its first inverted element.
void tet_io_finish(TetMesh& mesh, const std::string& where,
                   const std::vector<std::size_t>& line_of_tet) {
  std::size_t negative = 0;
  std::size_t positive = 0;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const TetIndices& tet = mesh.tets[t];
    if (tet[0] >= mesh.nodes.size() || tet[1] >= mesh.nodes.size() || tet[2] >= mesh.nodes.size() ||
        tet[3] >= mesh.nodes.size()) {
      continue;  // validation reports it
    }
    const double v = mesh.signed_volume(t);
    negative += v < 0.0 ? 1u : 0u;
    positive += v > 0.0 ? 1u : 0u;
  }
  if (negative > 0 && positive == 0) {
    for (TetIndices& tet : mesh.tets) {
      std::swap(tet[1], tet[2]);
    }
  }
  if (auto problem = find_tet_mesh_problem(mesh)) {
    // A file has no units (TetMesh::scale comes after): volumes are in its units cubed.
    std::string& message = problem->message;
    if (const auto unit = message.rfind(" m^3)"); unit != std::string::npos) {
      message.replace(unit, 5, " file units^3)");
    }
    if (problem->element && *problem->element < line_of_tet.size()) {
      throw Error(where + ":" + std::to_string(line_of_tet[*problem->element]), message);
    }
    throw Error(where, message);
  }
}

// ---- Gmsh MSH 4.1 ----------------------------------------------------------------------------

struct GmshElementType {
  int type;
  int nodes;
  const char* name;
};

// The element types of the MSH format (gmsh.info/doc/texinfo/gmsh.html#MSH-file-format).
constexpr GmshElementType kGmshElementTypes[] = {
    {1, 2, "2-node line"},
    {2, 3, "3-node triangle"},
    {3, 4, "4-node quadrangle"},
    {4, 4, "4-node tetrahedron"},
    {5, 8, "8-node hexahedron"},
    {6, 6, "6-node prism"},
    {7, 5, "5-node pyramid"},
    {8, 3, "3-node line"},
    {9, 6, "6-node triangle"},
    {10, 9, "9-node quadrangle"},
    {11, 10, "10-node second-order tetrahedron"},
    {12, 27, "27-node hexahedron"},
    {13, 18, "18-node prism"},
    {14, 14, "14-node pyramid"},
    {15, 1, "1-node point"},
    {16, 8, "8-node quadrangle"},
    {17, 20, "20-node hexahedron"},
    {18, 15, "15-node prism"},
    {19, 13, "13-node pyramid"},
    {20, 9, "9-node triangle"},
    {21, 10, "10-node triangle"},
    {22, 12, "12-node triangle"},
    {23, 15, "15-node triangle"},
    {24, 15, "15-node triangle"},
    {25, 21, "21-node triangle"},
    {26, 4, "4-node line"},
    {27, 5, "5-node line"},
    {28, 6, "6-node line"},
    {29, 20, "20-node tetrahedron"},
    {30, 35, "35-node tetrahedron"},
    {31, 56, "56-node tetrahedron"},
    {92, 64, "64-node hexahedron"},
    {93, 125, "125-node hexahedron"},
};

const GmshElementType* gmsh_element_type(std::int64_t type) {
  for (const GmshElementType& t : kGmshElementTypes) {
    if (t.type == type) {
      return &t;
    }
  }
  return nullptr;
}

std::string gmsh_type_refusal(std::int64_t type) {
  const GmshElementType* known = gmsh_element_type(type);
  return "element type " + std::to_string(type) +
         (known ? " (" + std::string(known->name) + ")" : std::string()) +
         " is not supported: linear tetrahedra only";
}

// Skips an unknown section up to its $End line.
void gmsh_skip_section(TetIoText& in, std::string_view name) {
  const std::string end = "$End" + std::string(name.substr(1));
  while (true) {
    const auto t = in.try_token();
    if (!t) {
      in.fail("section " + std::string(name) + " has no " + end + " (the file is truncated)");
    }
    if (*t == end) {
      return;
    }
  }
}

// $Entities: per volume entity tag, its first physical tag (when it has any).
std::vector<std::pair<std::int64_t, std::int64_t>> gmsh_read_entities(TetIoText& in) {
  constexpr std::int64_t kTagMax = std::numeric_limits<std::int32_t>::max();
  std::array<std::size_t, 4> counts{};
  for (std::size_t d = 0; d < 4; ++d) {
    counts[d] = in.count("entity count", 8);
  }
  std::vector<std::pair<std::int64_t, std::int64_t>> volume_physical;
  volume_physical.reserve(counts[3]);
  for (std::size_t d = 0; d < 4; ++d) {
    for (std::size_t e = 0; e < counts[d]; ++e) {
      const std::int64_t tag = in.integer("entity tag", -kTagMax, kTagMax);
      const int coordinates = d == 0 ? 3 : 6;  // a point, else a bounding box
      for (int c = 0; c < coordinates; ++c) {
        (void)in.real("entity coordinate");
      }
      const std::size_t physical_count = in.count("physical tag count", 2);
      std::optional<std::int64_t> first_physical;
      for (std::size_t p = 0; p < physical_count; ++p) {
        const std::int64_t physical = in.integer("physical tag", -kTagMax, kTagMax);
        if (!first_physical) {
          first_physical = physical;
        }
      }
      if (d > 0) {
        const std::size_t bounding = in.count("bounding entity count", 2);
        for (std::size_t b = 0; b < bounding; ++b) {
          (void)in.integer("bounding entity tag", -kTagMax, kTagMax);
        }
      }
      if (d == 3 && first_physical) {
        volume_physical.emplace_back(tag, *first_physical);
      }
    }
  }
  in.expect("$EndEntities");
  std::sort(volume_physical.begin(), volume_physical.end());
  return volume_physical;
}

}  // namespace

TetMesh parse_gmsh_msh4(std::string_view text, std::string_view source) {
  TetIoText in(text, std::string(source));
  const auto first = in.try_token();
  if (!first || *first != "$MeshFormat") {
    in.fail("not a Gmsh MSH file: it does not begin with $MeshFormat");
  }
  const std::string_view version = in.token("the MSH version");
  const std::string_view file_type = in.token("the MSH file type (0 for ASCII)");
  (void)in.token("the MSH data size");
  if (file_type != "0") {
    in.fail("binary MSH is not supported; save as ASCII 4.1");
  }
  if (version != "4.1") {
    in.fail("MSH version " + TetIoText::excerpt(version) +
            " is not supported; save as ASCII 4.1 (gmsh -format msh41)");
  }
  in.expect("$EndMeshFormat");

  constexpr std::int64_t kTagMax = std::numeric_limits<std::int64_t>::max() / 2;
  std::vector<std::pair<std::int64_t, std::int64_t>> volume_physical;
  std::vector<std::pair<std::int64_t, std::uint32_t>> node_of_tag;  // sorted by tag
  TetMesh mesh;
  std::vector<std::size_t> line_of_tet;
  bool have_nodes = false;
  bool have_elements = false;
  while (const auto section = in.try_token()) {
    if (*section == "$Entities") {
      volume_physical = gmsh_read_entities(in);
    } else if (*section == "$Nodes") {
      if (have_nodes) {
        in.fail("a second $Nodes section (one mesh per file)");
      }
      have_nodes = true;
      const std::size_t blocks = in.count("node block count", 8);
      const std::size_t total = in.count("node count", 8);
      (void)in.integer("the smallest node tag", 0, kTagMax);
      (void)in.integer("the largest node tag", 0, kTagMax);
      mesh.nodes.reserve(total);
      node_of_tag.reserve(total);
      for (std::size_t b = 0; b < blocks; ++b) {
        const std::int64_t dim = in.integer("node block dimension", 0, 3);
        (void)in.integer("node block entity tag", -kTagMax, kTagMax);
        const std::int64_t parametric = in.integer("node block parametric flag", 0, 1);
        const std::size_t n = in.count("node count of the block", 8);
        if (mesh.nodes.size() + n > total) {
          in.fail("the node blocks hold more than the " + std::to_string(total) +
                  " nodes the $Nodes header declares");
        }
        const std::size_t base = mesh.nodes.size();
        for (std::size_t i = 0; i < n; ++i) {
          const std::int64_t tag = in.integer("node tag", 1, kTagMax);
          node_of_tag.emplace_back(tag, static_cast<std::uint32_t>(base + i));
        }
        const std::int64_t extra = parametric ? dim : 0;  // u, v, w after x y z
        for (std::size_t i = 0; i < n; ++i) {
          Vec3 p;
          p.x() = in.real("node x coordinate");
          p.y() = in.real("node y coordinate");
          p.z() = in.real("node z coordinate");
          for (std::int64_t k = 0; k < extra; ++k) {
            (void)in.real("node parametric coordinate");
          }
          mesh.nodes.push_back(p);
        }
      }
      if (mesh.nodes.size() != total) {
        in.fail("the node blocks hold " + std::to_string(mesh.nodes.size()) +
                " nodes, the $Nodes header declares " + std::to_string(total));
      }
      in.expect("$EndNodes");
      std::sort(node_of_tag.begin(), node_of_tag.end());
      for (std::size_t i = 1; i < node_of_tag.size(); ++i) {
        if (node_of_tag[i].first == node_of_tag[i - 1].first) {
          in.fail("node tag " + std::to_string(node_of_tag[i].first) + " appears twice in $Nodes");
        }
      }
    } else if (*section == "$Elements") {
      if (!have_nodes) {
        in.fail("$Elements before $Nodes");
      }
      if (have_elements) {
        in.fail("a second $Elements section (one mesh per file)");
      }
      have_elements = true;
      const std::size_t blocks = in.count("element block count", 8);
      const std::size_t total = in.count("element count", 4);
      (void)in.integer("the smallest element tag", 0, kTagMax);
      (void)in.integer("the largest element tag", 0, kTagMax);
      std::size_t seen = 0;
      for (std::size_t b = 0; b < blocks; ++b) {
        const std::int64_t dim = in.integer("element block dimension", 0, 3);
        const std::int64_t entity = in.integer("element block entity tag", -kTagMax, kTagMax);
        const std::int64_t type = in.integer("element type", 0, kTagMax);
        const GmshElementType* known = gmsh_element_type(type);
        const std::size_t n = in.count("element count of the block",
                                       2 * static_cast<std::size_t>(known ? known->nodes + 1 : 1));
        seen += n;
        if (seen > total) {
          in.fail("the element blocks hold more than the " + std::to_string(total) +
                  " elements the $Elements header declares");
        }
        if (dim == 3 && type != 4) {
          in.fail(gmsh_type_refusal(type));
        }
        if (dim < 3) {
          if (known == nullptr) {
            in.fail("element type " + std::to_string(type) + " is not an MSH element type");
          }
          // Surface, line and point elements a mesher writes beside the volume.
          for (std::size_t i = 0; i < n * static_cast<std::size_t>(known->nodes + 1); ++i) {
            (void)in.integer("element or node tag", 0, kTagMax);
          }
          continue;
        }
        std::int32_t region = 0;
        const auto physical = std::lower_bound(volume_physical.begin(), volume_physical.end(),
                                               std::make_pair(entity, kTagMax * -2));
        const std::int64_t region_tag =
            physical != volume_physical.end() && physical->first == entity ? physical->second
                                                                           : entity;
        if (region_tag < std::numeric_limits<std::int32_t>::min() ||
            region_tag > std::numeric_limits<std::int32_t>::max()) {
          in.fail("region tag " + std::to_string(region_tag) + " is out of range");
        }
        region = static_cast<std::int32_t>(region_tag);
        mesh.tets.reserve(mesh.tets.size() + n);
        mesh.regions.reserve(mesh.tets.size() + n);
        line_of_tet.reserve(mesh.tets.size() + n);
        for (std::size_t i = 0; i < n; ++i) {
          const std::int64_t element_tag = in.integer("element tag", 0, kTagMax);
          const std::size_t line = in.line();
          TetIndices tet{};
          for (std::size_t k = 0; k < 4; ++k) {
            const std::int64_t tag = in.integer("node tag", 0, kTagMax);
            const auto it = std::lower_bound(node_of_tag.begin(), node_of_tag.end(),
                                             std::make_pair(tag, std::uint32_t{0}));
            if (it == node_of_tag.end() || it->first != tag) {
              in.fail("element " + std::to_string(mesh.tets.size()) + " (tag " +
                      std::to_string(element_tag) + "): node tag " + std::to_string(tag) +
                      " is not in $Nodes");
            }
            tet[k] = it->second;
          }
          mesh.tets.push_back(tet);
          mesh.regions.push_back(region);
          line_of_tet.push_back(line);
        }
      }
      if (seen != total) {
        in.fail("the element blocks hold " + std::to_string(seen) +
                " elements, the $Elements header declares " + std::to_string(total));
      }
      in.expect("$EndElements");
    } else if (section->size() > 1 && section->front() == '$' && section->substr(0, 4) != "$End") {
      gmsh_skip_section(in, *section);  // $PhysicalNames, $Comments, $NodeData, ...
    } else {
      in.fail("expected a section ($Nodes, $Elements, ...), found '" +
              TetIoText::excerpt(*section) + "'");
    }
  }
  if (!have_nodes || !have_elements) {
    in.fail(std::string("the file has no ") + (have_nodes ? "$Elements" : "$Nodes") + " section");
  }
  if (mesh.tets.empty()) {
    throw Error(in.where(),
                "the file holds no tetrahedra (a surface mesh? mesh the volume: "
                "gmsh -3)");
  }
  tet_io_finish(mesh, in.where(), line_of_tet);
  return mesh;
}

TetMesh read_gmsh_msh4(const std::filesystem::path& path) {
  std::string text;
  try {
    text = read_text_file(path, kTetMeshMaxBytes, "Gmsh mesh");
  } catch (const Error&) {
    // A binary MSH holds NUL bytes, which the text reader refuses as "not text": say which
    // format it is instead, from its first line.
    std::ifstream head(path, std::ios::binary);
    char buffer[64] = {};
    head.read(buffer, sizeof buffer);
    const auto got = static_cast<std::size_t>(std::max<std::streamsize>(head.gcount(), 0));
    TetIoText start(std::string_view(buffer, got), path.string());
    const auto keyword = start.try_token();
    const auto version = start.try_token();
    const auto file_type = start.try_token();
    if (keyword == "$MeshFormat" && version && file_type == "1") {
      throw Error(path.string(), "binary MSH is not supported; save as ASCII 4.1");
    }
    throw;
  }
  return parse_gmsh_msh4(text, path.string());
}

// ---- TetGen ----------------------------------------------------------------------------------

TetMesh parse_tetgen(std::string_view node_text, std::string_view ele_text,
                     std::string_view source) {
  TetMesh mesh;
  const std::string stem(source);
  TetIoText nodes(node_text, stem + ".node", true);
  const std::size_t node_count = nodes.count("node count", 8);
  const std::int64_t dimension = nodes.integer("dimension", 0, 1000);
  if (dimension != 3) {
    nodes.fail("dimension " + std::to_string(dimension) + ": a tet mesh is 3-dimensional");
  }
  const std::size_t node_attributes = nodes.count("node attribute count", 2);
  const std::int64_t node_markers = nodes.integer("boundary marker flag", 0, 1);
  std::int64_t base = 0;
  mesh.nodes.reserve(node_count);
  for (std::size_t i = 0; i < node_count; ++i) {
    const std::int64_t number = nodes.integer("node number", 0, kTetIoMaxCount);
    if (i == 0) {
      base = number;  // TetGen numbers from 0 or 1, as its first node says
      if (base > 1) {
        nodes.fail("the first node is numbered " + std::to_string(base) +
                   "; TetGen numbers nodes from 0 or 1");
      }
    } else if (number != base + static_cast<std::int64_t>(i)) {
      nodes.fail("node number " + std::to_string(number) + " where " +
                 std::to_string(base + static_cast<std::int64_t>(i)) +
                 " was expected (nodes are numbered consecutively)");
    }
    Vec3 p;
    p.x() = nodes.real("node x coordinate");
    p.y() = nodes.real("node y coordinate");
    p.z() = nodes.real("node z coordinate");
    for (std::size_t a = 0; a < node_attributes; ++a) {
      (void)nodes.real("node attribute");
    }
    if (node_markers) {
      (void)nodes.integer("boundary marker", std::numeric_limits<std::int32_t>::min(),
                          std::numeric_limits<std::int32_t>::max());
    }
    mesh.nodes.push_back(p);
  }
  if (const auto extra = nodes.try_token()) {
    nodes.fail("more than the " + std::to_string(node_count) + " nodes the header declares ('" +
               TetIoText::excerpt(*extra) + "')");
  }

  TetIoText elements(ele_text, stem + ".ele", true);
  const std::size_t tet_count = elements.count("element count", 10);
  const std::int64_t per_tet = elements.integer("nodes per element", 0, 1000);
  if (per_tet != 4) {
    elements.fail(std::to_string(per_tet) +
                  "-node elements are not supported: linear (4-node) tetrahedra only");
  }
  const std::size_t attributes = elements.count("element attribute count", 2);
  mesh.tets.reserve(tet_count);
  if (attributes > 0) {
    mesh.regions.reserve(tet_count);
  }
  std::vector<std::size_t> line_of_tet;
  line_of_tet.reserve(tet_count);
  for (std::size_t t = 0; t < tet_count; ++t) {
    (void)elements.integer("element number", std::numeric_limits<std::int64_t>::min(),
                           std::numeric_limits<std::int64_t>::max());
    const std::size_t line = elements.line();
    TetIndices tet{};
    for (std::size_t k = 0; k < 4; ++k) {
      const std::int64_t number =
          elements.integer("node number", std::numeric_limits<std::int64_t>::min() / 2,
                           std::numeric_limits<std::int64_t>::max() / 2);
      const std::int64_t index = number - base;
      if (index < 0 || index >= static_cast<std::int64_t>(mesh.nodes.size())) {
        elements.fail("element " + std::to_string(t) + ": node " + std::to_string(number) +
                      " out of range (the .node file has " + std::to_string(mesh.nodes.size()) +
                      " nodes numbered from " + std::to_string(base) + ")");
      }
      tet[k] = static_cast<std::uint32_t>(index);
    }
    for (std::size_t a = 0; a < attributes; ++a) {
      const double value = elements.real("element attribute");
      if (a == 0) {
        // The region attribute (tetgen -A) is an integer written as a number.
        if (value != std::floor(value) || value < std::numeric_limits<std::int32_t>::min() ||
            value > std::numeric_limits<std::int32_t>::max()) {
          elements.fail("element " + std::to_string(t) +
                        ": the region attribute is not a 32-bit integer");
        }
        mesh.regions.push_back(static_cast<std::int32_t>(value));
      }
    }
    mesh.tets.push_back(tet);
    line_of_tet.push_back(line);
  }
  if (const auto extra = elements.try_token()) {
    elements.fail("more than the " + std::to_string(tet_count) +
                  " elements the header declares ('" + TetIoText::excerpt(*extra) + "')");
  }
  tet_io_finish(mesh, elements.where(), line_of_tet);
  return mesh;
}

TetMesh read_tetgen(const std::filesystem::path& node_or_ele_path) {
  std::filesystem::path stem = node_or_ele_path;
  const std::string ext = tet_io_lower(stem.extension().string());
  if (ext != ".node" && ext != ".ele") {
    throw Error(node_or_ele_path.string(), "expected a TetGen .node or .ele file");
  }
  stem.replace_extension();
  std::filesystem::path node_path = stem;
  node_path += ".node";
  std::filesystem::path ele_path = stem;
  ele_path += ".ele";
  const std::string node_text = read_text_file(node_path, kTetMeshMaxBytes, "TetGen node file");
  const std::string ele_text = read_text_file(ele_path, kTetMeshMaxBytes, "TetGen element file");
  return parse_tetgen(node_text, ele_text, stem.string());
}

// ---- Legacy VTK ------------------------------------------------------------------------------

namespace {

struct VtkCellType {
  int type;
  const char* name;
  bool volume;
};

// Cell types of the legacy format (vtkCellType.h); those of dimension < 3 are skipped.
constexpr VtkCellType kVtkCellTypes[] = {
    {1, "vertex", false},
    {2, "poly vertex", false},
    {3, "line", false},
    {4, "poly line", false},
    {5, "triangle", false},
    {6, "triangle strip", false},
    {7, "polygon", false},
    {8, "pixel", false},
    {9, "quad", false},
    {10, "tetra", true},
    {11, "voxel", true},
    {12, "hexahedron", true},
    {13, "wedge", true},
    {14, "pyramid", true},
    {15, "pentagonal prism", true},
    {16, "hexagonal prism", true},
    {21, "quadratic edge", false},
    {22, "quadratic triangle", false},
    {23, "quadratic quad", false},
    {24, "quadratic tetra", true},
    {25, "quadratic hexahedron", true},
    {26, "quadratic wedge", true},
    {27, "quadratic pyramid", true},
    {28, "biquadratic quad", false},
    {29, "triquadratic hexahedron", true},
    {30, "quadratic linear quad", false},
    {31, "quadratic linear wedge", true},
    {32, "biquadratic quadratic wedge", true},
    {33, "biquadratic quadratic hexahedron", true},
    {34, "biquadratic triangle", false},
    {35, "cubic line", false},
    {36, "quadratic polygon", false},
    {42, "polyhedron", true},
    {68, "Lagrange curve", false},
    {69, "Lagrange triangle", false},
    {70, "Lagrange quadrilateral", false},
    {71, "Lagrange tetrahedron", true},
    {72, "Lagrange hexahedron", true},
    {73, "Lagrange wedge", true},
    {74, "Lagrange pyramid", true},
};

const VtkCellType* vtk_cell_type(std::int64_t type) {
  for (const VtkCellType& t : kVtkCellTypes) {
    if (t.type == type) {
      return &t;
    }
  }
  return nullptr;
}

// The names a region array goes by, best first.
int vtk_region_rank(std::string_view name) {
  if (name == "region") {
    return 0;
  }
  if (name == "gmsh:physical") {
    return 1;
  }
  if (name == "CellEntityIds") {
    return 2;
  }
  return -1;
}

// Reads `n` numbers of an attribute array; when `keep`, returns them (else skips them).
std::vector<double> vtk_read_values(TetIoText& in, std::size_t n, bool keep,
                                    std::string_view what) {
  std::vector<double> values;
  if (keep) {
    values.reserve(n);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double v = in.real(what);
    if (keep) {
      values.push_back(v);
    }
  }
  return values;
}

// A METADATA block (VTK 5.1) runs to the next blank line.
void vtk_skip_metadata(TetIoText& in) {
  (void)in.rest_of_line();
  while (in.remaining() > 0) {
    if (in.rest_of_line().empty()) {
      return;
    }
  }
}

std::size_t vtk_checked_product(TetIoText& in, std::size_t a, std::size_t b,
                                std::string_view what) {
  if (a != 0 && b > (in.remaining() + 2) / 2 / a) {
    in.fail(std::string(what) +
            " is more than the rest of the file can hold (truncated or "
            "corrupt)");
  }
  return a * b;
}

}  // namespace

TetMesh parse_vtk_unstructured(std::string_view text, std::string_view source) {
  TetIoText in(text, std::string(source));
  const std::string_view header = in.rest_of_line();
  if (header.starts_with("<?xml") || header.starts_with("<VTKFile")) {
    in.fail("an XML VTK file (.vtu) is not supported; save as legacy ASCII .vtk");
  }
  if (!tet_io_lower(header).starts_with("# vtk datafile")) {
    in.fail("not a legacy VTK file: the first line is not '# vtk DataFile Version ...'");
  }
  (void)in.rest_of_line();  // the title: free text
  const std::string_view format = in.token("ASCII or BINARY");
  if (tet_io_iequals(format, "BINARY")) {
    in.fail("binary VTK is not supported; save as ASCII");
  }
  if (!tet_io_iequals(format, "ASCII")) {
    in.fail("expected ASCII, found '" + TetIoText::excerpt(format) + "'");
  }
  if (!tet_io_iequals(in.token("DATASET"), "DATASET")) {
    in.fail("expected DATASET UNSTRUCTURED_GRID");
  }
  const std::string_view dataset = in.token("the dataset type");
  if (!tet_io_iequals(dataset, "UNSTRUCTURED_GRID")) {
    in.fail("DATASET " + TetIoText::excerpt(dataset) +
            " is not supported: an UNSTRUCTURED_GRID of tetrahedra only");
  }

  TetMesh mesh;
  bool have_points = false;
  // Cells as offsets into one connectivity array, whichever way the file lists them.
  std::vector<std::uint64_t> offsets;
  std::vector<std::int64_t> connectivity;
  std::vector<std::size_t> line_of_cell;
  bool have_cells = false;
  std::vector<std::int64_t> types;
  std::size_t types_line = 0;
  std::vector<double> regions;
  int region_rank = 3;
  std::size_t regions_line = 0;
  // Which attribute section the arrays belong to: 0 none yet, 1 cell data, 2 point data.
  int attribute_section = 0;
  std::size_t attribute_count = 0;

  const auto take_region_array = [&](std::string_view name, std::size_t components,
                                     std::size_t tuples, std::string_view what) {
    const int rank = vtk_region_rank(name);
    const bool keep = attribute_section == 1 && components == 1 && rank >= 0 && rank < region_rank;
    const std::size_t line = in.line();
    std::vector<double> values =
        vtk_read_values(in, vtk_checked_product(in, components, tuples, what), keep, what);
    if (keep) {
      regions = std::move(values);
      region_rank = rank;
      regions_line = line;
    }
  };

  while (const auto keyword_token = in.try_token()) {
    const std::string keyword = tet_io_lower(*keyword_token);
    if (keyword == "points") {
      if (have_points) {
        in.fail("a second POINTS section");
      }
      have_points = true;
      const std::size_t n = in.count("point count", 6);
      (void)in.token("the point data type");
      mesh.nodes.reserve(n);
      for (std::size_t i = 0; i < n; ++i) {
        Vec3 p;
        p.x() = in.real("point x coordinate");
        p.y() = in.real("point y coordinate");
        p.z() = in.real("point z coordinate");
        mesh.nodes.push_back(p);
      }
    } else if (keyword == "cells") {
      if (have_cells) {
        in.fail("a second CELLS section");
      }
      have_cells = true;
      const std::size_t first = in.count("cell count", 2);
      const std::size_t second = in.count("cell list size", 2);
      const auto next = in.peek();
      if (next && tet_io_iequals(*next, "OFFSETS")) {
        // VTK 5.1: OFFSETS (cells + 1 of them) then CONNECTIVITY.
        (void)in.token("OFFSETS");
        (void)in.token("the offsets' data type");
        if (first == 0) {
          in.fail("CELLS declares no offsets");
        }
        offsets.reserve(first);
        for (std::size_t i = 0; i < first; ++i) {
          const auto o = static_cast<std::uint64_t>(in.integer("cell offset", 0, kTetIoMaxCount));
          if (i == 0 ? o != 0 : o < offsets.back()) {
            in.fail("cell offsets must start at 0 and never decrease");
          }
          offsets.push_back(o);
        }
        if (offsets.back() != second) {
          in.fail("the last cell offset is " + std::to_string(offsets.back()) +
                  ", the connectivity holds " + std::to_string(second));
        }
        if (!tet_io_iequals(in.token("CONNECTIVITY"), "CONNECTIVITY")) {
          in.fail("expected CONNECTIVITY after the cell offsets");
        }
        (void)in.token("the connectivity's data type");
        connectivity.reserve(second);
        line_of_cell.reserve(first - 1);
        for (std::size_t c = 0; c + 1 < first; ++c) {
          for (std::uint64_t k = offsets[c]; k < offsets[c + 1]; ++k) {
            connectivity.push_back(in.integer("point index", 0, kTetIoMaxCount));
            if (k == offsets[c]) {
              line_of_cell.push_back(in.line());
            }
          }
          if (offsets[c] == offsets[c + 1]) {
            line_of_cell.push_back(in.line());
          }
        }
      } else {
        // Legacy: per cell, its point count then its point indices.
        offsets.reserve(first + 1);
        offsets.push_back(0);
        connectivity.reserve(second);
        line_of_cell.reserve(first);
        std::size_t read = 0;
        for (std::size_t c = 0; c < first; ++c) {
          const auto k = static_cast<std::size_t>(in.integer("cell point count", 0, 1000));
          line_of_cell.push_back(in.line());
          read += k + 1;
          if (read > second) {
            in.fail("the cells hold more than the " + std::to_string(second) +
                    " numbers CELLS declares");
          }
          for (std::size_t i = 0; i < k; ++i) {
            connectivity.push_back(in.integer("point index", 0, kTetIoMaxCount));
          }
          offsets.push_back(connectivity.size());
        }
        if (read != second) {
          in.fail("the cells hold " + std::to_string(read) + " numbers, CELLS declares " +
                  std::to_string(second));
        }
      }
    } else if (keyword == "cell_types") {
      const std::size_t n = in.count("cell type count", 2);
      types_line = in.line();
      types.reserve(n);
      for (std::size_t i = 0; i < n; ++i) {
        types.push_back(in.integer("cell type", 0, 1000));
      }
    } else if (keyword == "cell_data" || keyword == "point_data") {
      attribute_section = keyword == "cell_data" ? 1 : 2;
      attribute_count =
          in.count(keyword == "cell_data" ? "cell data count" : "point data count", 2);
    } else if (keyword == "scalars") {
      const std::string name(in.token("the array name"));
      (void)in.token("the array data type");
      // An optional component count ends the SCALARS line; LOOKUP_TABLE, when present, is next.
      std::size_t components = 1;
      const std::string_view rest = in.rest_of_line();
      if (!rest.empty()) {
        int c = 0;
        const auto [ptr, ec] = std::from_chars(rest.data(), rest.data() + rest.size(), c);
        if (ec != std::errc() || ptr != rest.data() + rest.size() || c < 1 || c > 4) {
          in.fail("expected the component count (1 to 4) after SCALARS " +
                  TetIoText::excerpt(name) + ", found '" + TetIoText::excerpt(rest) + "'");
        }
        components = static_cast<std::size_t>(c);
      }
      const auto next = in.peek();
      if (next && tet_io_iequals(*next, "LOOKUP_TABLE")) {
        (void)in.token("LOOKUP_TABLE");
        (void)in.token("the lookup table name");
      }
      take_region_array(name, components, attribute_count, "scalar value");
    } else if (keyword == "field") {
      (void)in.token("the field name");
      const std::size_t arrays = in.count("field array count", 8);
      for (std::size_t a = 0; a < arrays; ++a) {
        const std::string name(in.token("the field array name"));
        const auto components =
            static_cast<std::size_t>(in.integer("the field array's component count", 1, 1000));
        const std::size_t tuples = in.count("the field array's tuple count", 2);
        (void)in.token("the field array's data type");
        if (tuples != attribute_count && attribute_section == 1 && vtk_region_rank(name) >= 0) {
          in.fail("the array " + TetIoText::excerpt(name) + " has " + std::to_string(tuples) +
                  " values, CELL_DATA declares " + std::to_string(attribute_count));
        }
        take_region_array(name, components, tuples, "field value");
        const auto next = in.peek();
        if (next && tet_io_iequals(*next, "METADATA")) {
          (void)in.token("METADATA");
          vtk_skip_metadata(in);
        }
      }
    } else if (keyword == "vectors" || keyword == "normals") {
      (void)in.token("the array name");
      (void)in.token("the array data type");
      take_region_array("", 3, attribute_count, "vector value");
    } else if (keyword == "tensors") {
      (void)in.token("the array name");
      (void)in.token("the array data type");
      take_region_array("", 9, attribute_count, "tensor value");
    } else if (keyword == "texture_coordinates") {
      (void)in.token("the array name");
      const auto dim = static_cast<std::size_t>(in.integer("the texture dimension", 1, 3));
      (void)in.token("the array data type");
      take_region_array("", dim, attribute_count, "texture coordinate");
    } else if (keyword == "color_scalars") {
      (void)in.token("the array name");
      const auto values = static_cast<std::size_t>(in.integer("the colour count", 1, 4));
      take_region_array("", values, attribute_count, "colour value");
    } else if (keyword == "lookup_table") {
      (void)in.token("the lookup table name");
      const std::size_t size = in.count("the lookup table size", 8);
      take_region_array("", 4, size, "lookup table value");
    } else if (keyword == "metadata") {
      vtk_skip_metadata(in);
    } else {
      in.fail("unexpected '" + TetIoText::excerpt(*keyword_token) +
              "' (expected POINTS, CELLS, CELL_TYPES or CELL_DATA)");
    }
  }
  if (!have_points) {
    in.fail("the file has no POINTS");
  }
  if (!have_cells) {
    in.fail("the file has no CELLS");
  }
  const std::size_t cell_count = offsets.empty() ? 0 : offsets.size() - 1;
  if (types_line == 0 && cell_count > 0) {
    in.fail("the file has no CELL_TYPES");
  }
  if (types.size() != cell_count) {
    throw Error(in.where() + ":" + std::to_string(types_line),
                "CELL_TYPES lists " + std::to_string(types.size()) + " types for " +
                    std::to_string(cell_count) + " cells");
  }
  if (!regions.empty() && regions.size() != cell_count) {
    throw Error(in.where() + ":" + std::to_string(regions_line),
                "the region array has " + std::to_string(regions.size()) + " values for " +
                    std::to_string(cell_count) + " cells");
  }

  std::vector<std::size_t> line_of_tet;
  for (std::size_t c = 0; c < cell_count; ++c) {
    const std::string where = in.where() + ":" + std::to_string(line_of_cell[c]);
    const VtkCellType* type = vtk_cell_type(types[c]);
    if (types[c] != 10) {
      if (type != nullptr && !type->volume) {
        continue;  // a surface, line or point cell beside the volume
      }
      throw Error(where, "cell " + std::to_string(c) + ": cell type " + std::to_string(types[c]) +
                             (type ? " (" + std::string(type->name) + ")" : std::string()) +
                             " is not supported: linear tetrahedra only");
    }
    if (offsets[c + 1] - offsets[c] != 4) {
      throw Error(where, "cell " + std::to_string(c) + " is a tetra with " +
                             std::to_string(offsets[c + 1] - offsets[c]) +
                             " points; a tetra has 4");
    }
    TetIndices tet{};
    for (std::size_t k = 0; k < 4; ++k) {
      const std::int64_t index = connectivity[offsets[c] + k];
      if (index >= static_cast<std::int64_t>(mesh.nodes.size())) {
        throw Error(where, "element " + std::to_string(mesh.tets.size()) + " (cell " +
                               std::to_string(c) + "): node " + std::to_string(index) +
                               " out of range (the mesh has " + std::to_string(mesh.nodes.size()) +
                               " nodes)");
      }
      tet[k] = static_cast<std::uint32_t>(index);
    }
    if (!regions.empty()) {
      const double r = regions[c];
      if (r != std::floor(r) || r < std::numeric_limits<std::int32_t>::min() ||
          r > std::numeric_limits<std::int32_t>::max()) {
        throw Error(in.where() + ":" + std::to_string(regions_line),
                    "cell " + std::to_string(c) + ": the region value is not a 32-bit integer");
      }
      mesh.regions.push_back(static_cast<std::int32_t>(r));
    }
    mesh.tets.push_back(tet);
    line_of_tet.push_back(line_of_cell[c]);
  }
  if (mesh.tets.empty()) {
    throw Error(in.where(), "the file holds no tetrahedra (cell type 10)");
  }
  tet_io_finish(mesh, in.where(), line_of_tet);
  return mesh;
}

void write_tetgen(const TetMesh& mesh, const std::filesystem::path& path_without_extension) {
  std::string node = std::to_string(mesh.node_count()) + " 3 0 0\n";
  char line[128];
  for (std::size_t i = 0; i < mesh.node_count(); ++i) {
    const Vec3& p = mesh.nodes[i];
    std::snprintf(line, sizeof line, "%zu %.17g %.17g %.17g\n", i, p.x(), p.y(), p.z());
    node += line;
  }
  std::string ele = std::to_string(mesh.tet_count()) + " 4 1\n";
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    const TetIndices& k = mesh.tets[t];
    std::snprintf(line, sizeof line, "%zu %u %u %u %u %d\n", t, k[0], k[1], k[2], k[3],
                  mesh.region(t));
    ele += line;
  }
  // Both written to temporaries (core/atomic_file.h) before either is moved into place: a failed
  // write never leaves a new .node beside an old .ele (a pair that could load as a wrong mesh).
  const auto with = [&](const char* ext) {
    std::filesystem::path p = path_without_extension;
    p += ext;
    return p;
  };
  AtomicFile node_file(with(".node"));
  AtomicFile ele_file(with(".ele"));
  node_file.write(node);
  ele_file.write(ele);
  node_file.sync();
  ele_file.sync();
  node_file.commit();
  ele_file.commit();
}

TetMesh read_vtk_unstructured(const std::filesystem::path& path) {
  return parse_vtk_unstructured(read_text_file(path, kTetMeshMaxBytes, "VTK mesh"), path.string());
}

TetMesh read_tet_mesh(const std::filesystem::path& path) {
  const std::string ext = tet_io_lower(path.extension().string());
  if (ext == ".msh") {
    return read_gmsh_msh4(path);
  }
  if (ext == ".node" || ext == ".ele") {
    return read_tetgen(path);
  }
  if (ext == ".vtk") {
    return read_vtk_unstructured(path);
  }
  throw Error(path.string(),
              "not a tet mesh file: expected .msh (Gmsh 4.1 ASCII), .node/.ele "
              "(TetGen) or .vtk (legacy ASCII unstructured grid)");
}

bool is_tet_mesh_path(const std::filesystem::path& path) {
  const std::string ext = tet_io_lower(path.extension().string());
  return ext == ".msh" || ext == ".node" || ext == ".ele" || ext == ".vtk";
}

}  // namespace hapsim
