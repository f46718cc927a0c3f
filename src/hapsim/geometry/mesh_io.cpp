#include "hapsim/geometry/mesh_io.h"

#include "hapsim/core/atomic_file.h"
#include "hapsim/core/error.h"
#include "hapsim/core/isolated_call.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <spdlog/spdlog.h>
#include <assimp/Exporter.hpp>
#include <assimp/IOStream.hpp>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace hapsim {
namespace {

namespace fs = std::filesystem;

constexpr const char* kExpected =
    "expected a readable triangle mesh file (OBJ, STL, PLY, glTF/GLB, or another format Assimp "
    "reads)";

std::string lower_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d out;
  for (unsigned r = 0; r < 4; ++r) {
    for (unsigned c = 0; c < 4; ++c) {
      out(r, c) = static_cast<double>(m[r][c]);
    }
  }
  return out;
}

// Appends every triangle of every mesh instance in the node tree (iterative: a hostile file
// cannot overflow the stack with a deep hierarchy). Returns the number of skipped points/lines.
std::size_t gather_triangles(const aiScene& scene, TriangleMesh& out) {
  std::size_t skipped_primitives = 0;
  std::vector<std::pair<const aiNode*, Eigen::Matrix4d>> stack;
  if (scene.mRootNode != nullptr) {
    stack.emplace_back(scene.mRootNode, Eigen::Matrix4d::Identity());
  }
  while (!stack.empty()) {
    const auto [node, parent_X] = stack.back();
    stack.pop_back();
    const Eigen::Matrix4d X = parent_X * to_eigen(node->mTransformation);
    const Eigen::Matrix3d linear = X.topLeftCorner<3, 3>();
    const Eigen::Vector3d offset = X.topRightCorner<3, 1>();
    // A mirroring node transform turns winding inside out; swap to keep it outward.
    const bool mirror = linear.determinant() < 0.0;
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
      if (node->mMeshes[i] >= scene.mNumMeshes) {
        continue;
      }
      const aiMesh* mesh = scene.mMeshes[node->mMeshes[i]];
      if (mesh == nullptr || mesh->mVertices == nullptr) {
        continue;
      }
      const auto base = static_cast<std::uint32_t>(out.vertices.size());
      for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
        const aiVector3D& p = mesh->mVertices[v];
        out.vertices.push_back(linear * Vec3(p.x, p.y, p.z) + offset);
      }
      for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
        const aiFace& face = mesh->mFaces[f];
        if (face.mNumIndices != 3 || face.mIndices == nullptr) {
          ++skipped_primitives;
          continue;
        }
        TriangleIndices tri;
        for (int k = 0; k < 3; ++k) {
          // An index past this mesh's vertices stays out of range, for validation to report.
          tri[k] = face.mIndices[k] < mesh->mNumVertices ? base + face.mIndices[k] : kNoTriangle;
        }
        if (mirror) {
          std::swap(tri[1], tri[2]);
        }
        out.triangles.push_back(tri);
      }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c) {
      if (node->mChildren[c] != nullptr) {
        stack.emplace_back(node->mChildren[c], X);
      }
    }
  }
  return skipped_primitives;
}

// What the importer hands back: the triangles as read (node transforms applied, unscaled) and
// how many point/line primitives it skipped.
struct ImportedTriangles {
  TriangleMesh mesh;
  std::size_t skipped_primitives = 0;
};

ImportedTriangles import_triangles(const fs::path& path, bool weld) {
  const std::string where = path.string();
  Assimp::Importer importer;
  // Only what is needed to get triangles: no normal generation, no degenerate removal, no
  // "fixing" of invalid data — validation must see the file's real defects.
  unsigned flags = aiProcess_Triangulate | aiProcess_ValidateDataStructure;
  if (!weld) {
    flags |= aiProcess_JoinIdenticalVertices;  // keep the file's indexing where it has one
  }
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFile(where, flags);
  } catch (const std::exception& e) {  // e.g. bad_alloc from a lying size field
    throw Error(where, std::string("mesh importer failed: ") + e.what() + "; " + kExpected);
  }
  if (scene == nullptr) {
    throw Error(where,
                std::string("cannot read mesh: ") + importer.GetErrorString() + "; " + kExpected);
  }
  if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 && scene->mNumMeshes == 0) {
    throw Error(where, "file holds no meshes (incomplete scene); expected triangles");
  }
  ImportedTriangles out;
  out.skipped_primitives = gather_triangles(*scene, out.mesh);
  return out;
}

// The child's result through the pipe: counts, then the vertices and triangles as raw bytes.
std::string encode_triangles(const ImportedTriangles& in) {
  const std::uint64_t counts[3] = {in.mesh.vertices.size(), in.mesh.triangles.size(),
                                   in.skipped_primitives};
  std::string out(reinterpret_cast<const char*>(counts), sizeof counts);
  for (const Vec3& v : in.mesh.vertices) {
    out.append(reinterpret_cast<const char*>(v.data()), 3 * sizeof(double));
  }
  for (const TriangleIndices& t : in.mesh.triangles) {
    out.append(reinterpret_cast<const char*>(t.data()), 3 * sizeof(std::uint32_t));
  }
  return out;
}

void decode_triangles(const std::string& bytes, const std::string& where, TriangleMesh& mesh,
                      std::size_t& skipped_primitives) {
  std::uint64_t counts[3] = {0, 0, 0};
  const auto fail = [&] { throw Error(where, "the mesh importer's result was cut short"); };
  if (bytes.size() < sizeof counts) {
    fail();
  }
  std::memcpy(counts, bytes.data(), sizeof counts);
  const std::uint64_t vertex_bytes = counts[0] * 3 * sizeof(double);
  const std::uint64_t triangle_bytes = counts[1] * 3 * sizeof(std::uint32_t);
  if (counts[0] > bytes.size() || counts[1] > bytes.size() ||
      bytes.size() != sizeof counts + vertex_bytes + triangle_bytes) {
    fail();
  }
  const char* p = bytes.data() + sizeof counts;
  mesh.vertices.resize(counts[0]);
  for (Vec3& v : mesh.vertices) {
    std::memcpy(v.data(), p, 3 * sizeof(double));
    p += 3 * sizeof(double);
  }
  mesh.triangles.resize(counts[1]);
  for (TriangleIndices& t : mesh.triangles) {
    std::memcpy(t.data(), p, 3 * sizeof(std::uint32_t));
    p += 3 * sizeof(std::uint32_t);
  }
  skipped_primitives = counts[2];
}

void check_readable(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    // A loop of symlinks or a name too long is not "not found": say what the system said.
    throw Error(path.string(), (ec ? "cannot reach the mesh file (" + ec.message() + "); "
                                   : std::string("mesh file not found; ")) +
                                   kExpected);
  }
  if (!fs::is_regular_file(path, ec)) {
    throw Error(path.string(), std::string("not a regular file; ") + kExpected);
  }
  const auto size = fs::file_size(path, ec);
  if (ec) {
    throw Error(path.string(), "cannot determine file size (" + ec.message() + ")");
  }
  if (size == 0) {
    throw Error(path.string(), std::string("file is empty; ") + kExpected);
  }
  if (!std::ifstream(path, std::ios::binary).good()) {
    throw Error(path.string(), "file cannot be opened for reading (permissions?)");
  }
}

// Assimp's PLY reader looks for the header's end without a bound: a header whose 'end_header' is
// misspelt loops for ever (ASCII) or crashes (binary). A header is a few hundred bytes of lines.
void check_ply_header(const fs::path& path) {
  constexpr std::size_t kMaxHeaderBytes = 64 * 1024;
  std::string head(kMaxHeaderBytes, '\0');
  std::ifstream in(path, std::ios::binary);
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (head.rfind("ply", 0) != 0) {
    throw Error(path.string(),
                "not a PLY file (it does not start with 'ply'); " + std::string(kExpected));
  }
  for (std::size_t at = head.find("end_header"); at != std::string::npos;
       at = head.find("end_header", at + 1)) {
    const std::size_t after = at + std::string_view("end_header").size();
    const bool line_start = at > 0 && head[at - 1] == '\n';
    const bool line_end = after < head.size() && (head[after] == '\n' || head[after] == '\r');
    if (line_start && line_end) {
      return;
    }
  }
  throw Error(path.string(),
              "PLY header has no 'end_header' line in its first 64 kB; " + std::string(kExpected));
}

// Logs and notes every defect present; throws for those the policy refuses.
void apply_policy_messages(const fs::path& path, const MeshReport& found,
                           const ValidationPolicy& policy, std::vector<std::string>& notes) {
  std::string refused;
  for (std::size_t d = 0; d < kMeshDefectCount; ++d) {
    const auto defect = static_cast<MeshDefect>(d);
    const std::size_t n = found.count(defect);
    if (n == 0) {
      continue;
    }
    switch (policy[defect]) {
      case DefectAction::kIgnore:
        break;
      case DefectAction::kRefuse:
        refused += (refused.empty() ? "" : ", ") + std::string(to_string(defect)) + "=" +
                   std::to_string(n);
        break;
      case DefectAction::kWarn:
      case DefectAction::kRepair: {
        const bool repairable =
            defect != MeshDefect::kOpenEdge && defect != MeshDefect::kNonManifoldEdge;
        std::string note = std::string(to_string(defect)) + "=" + std::to_string(n);
        if (policy[defect] == DefectAction::kRepair) {
          note += repairable ? " (repairing)" : " (no automatic repair; accepted)";
        } else {
          note += " (accepted)";
        }
        spdlog::warn("{}: {}", path.string(), note);
        notes.push_back(std::move(note));
        break;
      }
    }
  }
  if (!refused.empty()) {
    throw Error(path.string(),
                "mesh refused by validation policy: " + refused + " (" + found.summary() + ")");
  }
}

bool indices_in_range(const TriangleMesh& mesh) {
  return std::all_of(mesh.triangles.begin(), mesh.triangles.end(), [&](const TriangleIndices& t) {
    return t[0] < mesh.vertices.size() && t[1] < mesh.vertices.size() &&
           t[2] < mesh.vertices.size();
  });
}

// Assimp's exporter id for an extension.
std::string export_format(const std::string& ext, bool binary) {
  if (ext == ".obj") {
    return "obj";
  }
  if (ext == ".stl") {
    return binary ? "stlb" : "stl";
  }
  if (ext == ".ply") {
    return binary ? "plyb" : "ply";
  }
  if (ext == ".gltf") {
    return "gltf2";
  }
  if (ext == ".glb") {
    return "glb2";
  }
  return {};
}

}  // namespace

bool is_mesh_file_supported(const fs::path& path) {
  const std::string ext = lower_extension(path);
  return !ext.empty() && Assimp::Importer().IsExtensionSupported(ext.c_str());
}

namespace {

// Checked before the importer runs (no child for a load that cannot succeed) and again by
// finish_imported_mesh, which a caller may reach directly.
void check_scale(const std::string& where, double scale) {
  if (!std::isfinite(scale) || scale == 0.0) {
    throw Error(where, "load scale must be finite and non-zero (metres per file unit), got " +
                           std::to_string(scale));
  }
}

}  // namespace

TriangleMesh load_mesh(const fs::path& path, const MeshLoadOptions& options, MeshReport* report) {
  const std::string where = path.string();
  check_scale(where, options.scale);
  check_readable(path);
  if (!is_mesh_file_supported(path)) {
    throw Error(where, "unsupported mesh format '" + path.extension().string() + "'; " + kExpected);
  }

  if (lower_extension(path) == ".ply") {
    check_ply_header(path);
  }
  TriangleMesh mesh;
  std::size_t skipped_primitives = 0;
  {
    // Assimp runs in a child process: a malformed file can hang it, crash it or trip one of its
    // assertions (seen with a few hundred bytes of PLY); here that is one error naming the file.
    std::error_code ec;
    const std::size_t file_bytes = fs::file_size(path, ec);
    IsolationLimits limits;
    limits.time_s = 30.0 + static_cast<double>(file_bytes) / 1e6;  // ~1 s per MB on a slow disk
    limits.memory_bytes = (std::size_t{2} << 30) + 32 * file_bytes;
    const std::string bytes = run_isolated(where, "the mesh importer (Assimp)", limits, [&] {
      return encode_triangles(import_triangles(path, options.weld));
    });
    decode_triangles(bytes, where, mesh, skipped_primitives);
  }
  return finish_imported_mesh(std::move(mesh), skipped_primitives, path, options, report);
}

TriangleMesh finish_imported_mesh(TriangleMesh mesh, std::size_t skipped_primitives,
                                  const fs::path& path, const MeshLoadOptions& options,
                                  MeshReport* report) {
  const std::string where = path.string();
  check_scale(where, options.scale);
  if (mesh.triangles.empty()) {
    throw Error(where, "file holds no triangles" +
                           (skipped_primitives > 0
                                ? " (only " + std::to_string(skipped_primitives) + " points/lines)"
                                : std::string()) +
                           "; expected a triangle mesh");
  }

  mesh.scale(options.scale);
  std::size_t welded = 0;
  if (options.weld) {
    const Box3 box = validate_mesh(mesh).bounds;  // finite vertices only
    const double diag = box.isEmpty() ? 0.0 : box.diagonal().norm();
    welded =
        weld_vertices(mesh, std::max(options.weld_tolerance_m, options.weld_tolerance_rel * diag));
  }

  MeshReport found = validate_mesh(mesh, options.validation);
  if (skipped_primitives > 0) {
    found.notes.push_back("skipped " + std::to_string(skipped_primitives) +
                          " point/line primitives");
    spdlog::warn("{}: {}", where, found.notes.back());
  }
  std::vector<std::string> notes;
  apply_policy_messages(path, found, options.policy, notes);
  found.notes.insert(found.notes.end(), notes.begin(), notes.end());

  const MeshRepairStats repairs = repair_mesh(mesh, options.policy, options.validation);
  if (repairs.any()) {
    found.notes.push_back("repaired: " + repairs.summary());
    spdlog::warn("{}: {}", where, found.notes.back());
    // A repair can expose a defect (orientation fixed → component now inside out); refuse
    // whatever the policy refuses in the result too.
    MeshReport after = validate_mesh(mesh, options.validation);
    std::vector<std::string> scratch;
    ValidationPolicy refuse_only = options.policy;
    for (DefectAction& a : refuse_only.actions) {
      a = a == DefectAction::kRefuse ? DefectAction::kRefuse : DefectAction::kIgnore;
    }
    apply_policy_messages(path, after, refuse_only, scratch);
    if (mesh.triangles.empty()) {
      throw Error(where, "no triangles left after repairs (" + repairs.summary() +
                             "); expected a triangle mesh");
    }
  }
  spdlog::debug("{}: loaded {} (welded {} vertices)", where, found.summary(), welded);

  mesh.vertex_normals.clear();
  if (options.compute_normals && indices_in_range(mesh)) {
    mesh.compute_vertex_normals();
  }
  if (report != nullptr) {
    *report = std::move(found);
  }
  return mesh;
}

namespace {

// Assimp's exporters write through an IOSystem; this one gathers each file in memory and writes it
// atomically when the exporter lets go of it (core/atomic_file.h): Assimp's own file writer does
// not check its writes, so a full disk gave "success" and a truncated mesh. An exporter may write
// more than one file (OBJ's .mtl) and may seek back (binary glTF's header).
struct ExportFailure {
  std::string file;     // the first file that could not be written, "" when all were
  std::string message;  // why
};

// Written when the exporter lets go of it: most exporters hold their stream in a unique_ptr and
// never call IOSystem::Close.
class MemoryStream final : public Assimp::IOStream {
 public:
  MemoryStream(std::string path, ExportFailure& failure)
      : path_(std::move(path)), failure_(failure) {}
  MemoryStream(const MemoryStream&) = delete;
  MemoryStream& operator=(const MemoryStream&) = delete;
  ~MemoryStream() override {
    if (!failure_.file.empty()) {
      return;  // one failure is said; later files are not written
    }
    try {
      write_file_atomically(path_, bytes_);
    } catch (const Error& e) {
      failure_.file = path_;
      failure_.message = e.detail();
    } catch (const std::exception& e) {
      failure_.file = path_;
      failure_.message = e.what();
    }
  }
  size_t Read(void* /*buffer*/, size_t /*size*/, size_t /*count*/) override { return 0; }
  size_t Write(const void* buffer, size_t size, size_t count) override {
    const std::size_t n = size * count;
    if (at_ + n > bytes_.size()) {
      bytes_.resize(at_ + n);
    }
    std::memcpy(bytes_.data() + at_, buffer, n);
    at_ += n;
    return count;
  }
  aiReturn Seek(size_t offset, aiOrigin origin) override {
    const std::size_t base = origin == aiOrigin_SET   ? 0
                             : origin == aiOrigin_CUR ? at_
                                                      : bytes_.size();
    at_ = base + offset;  // past the end, as a file allows (binary glTF skips its header first)
    if (at_ > bytes_.size()) {
      bytes_.resize(at_);
    }
    return aiReturn_SUCCESS;
  }
  [[nodiscard]] size_t Tell() const override { return at_; }
  [[nodiscard]] size_t FileSize() const override { return bytes_.size(); }
  void Flush() override {}

 private:
  std::string path_;
  ExportFailure& failure_;
  std::string bytes_;
  std::size_t at_ = 0;
};

class AtomicExportSystem final : public Assimp::IOSystem {
 public:
  explicit AtomicExportSystem(ExportFailure& failure) : failure_(failure) {}
  bool Exists(const char* file) const override { return fs::exists(file); }
  [[nodiscard]] char getOsSeparator() const override { return '/'; }
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    if (mode == nullptr || std::strchr(mode, 'w') == nullptr) {
      return nullptr;  // exporters only write
    }
    return new MemoryStream(file, failure_);  // NOLINT(cppcoreguidelines-owning-memory)
  }
  void Close(Assimp::IOStream* stream) override { delete stream; }

 private:
  ExportFailure& failure_;
};

}  // namespace

void save_mesh(const fs::path& path, const TriangleMesh& mesh, const MeshSaveOptions& options) {
  const std::string where = path.string();
  const std::string ext = lower_extension(path);
  const std::string format = export_format(ext, options.binary);
  if (format.empty()) {
    throw Error(where, "unsupported output format '" + path.extension().string() +
                           "'; expected .obj, .stl, .ply, .gltf or .glb");
  }
  if (mesh.triangles.empty()) {
    throw Error(where, "refusing to write a mesh without triangles");
  }
  if (!indices_in_range(mesh)) {
    throw Error(where, "refusing to write a mesh with out-of-range vertex indices");
  }
  if (!std::isfinite(options.scale) || options.scale == 0.0) {
    throw Error(where, "save scale must be finite and non-zero");
  }

  // aiScene owns and deletes everything below it (allocated with new, as Assimp expects).
  auto scene = std::make_unique<aiScene>();
  scene->mRootNode = new aiNode("hapsim_mesh");
  scene->mRootNode->mNumMeshes = 1;
  scene->mRootNode->mMeshes = new unsigned[1]{0};
  scene->mNumMaterials = 1;
  scene->mMaterials = new aiMaterial* [1] { new aiMaterial() };
  scene->mNumMeshes = 1;
  scene->mMeshes = new aiMesh* [1] { new aiMesh() };
  aiMesh& out = *scene->mMeshes[0];
  out.mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  out.mMaterialIndex = 0;
  out.mNumVertices = static_cast<unsigned>(mesh.vertices.size());
  out.mVertices = new aiVector3D[mesh.vertices.size()];
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Vec3 p = options.scale * mesh.vertices[v];
    out.mVertices[v] = aiVector3D(static_cast<ai_real>(p.x()), static_cast<ai_real>(p.y()),
                                  static_cast<ai_real>(p.z()));
  }
  if (mesh.vertex_normals.size() == mesh.vertices.size()) {
    out.mNormals = new aiVector3D[mesh.vertices.size()];
    const double sign = options.scale < 0.0 ? -1.0 : 1.0;
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
      const Vec3 n = sign * mesh.vertex_normals[v];
      out.mNormals[v] = aiVector3D(static_cast<ai_real>(n.x()), static_cast<ai_real>(n.y()),
                                   static_cast<ai_real>(n.z()));
    }
  }
  out.mNumFaces = static_cast<unsigned>(mesh.triangles.size());
  out.mFaces = new aiFace[mesh.triangles.size()];
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    TriangleIndices tri = mesh.triangles[t];
    if (options.scale < 0.0) {
      std::swap(tri[1], tri[2]);  // mirrored on writing: keep outward winding
    }
    aiFace& face = out.mFaces[t];
    face.mNumIndices = 3;
    face.mIndices = new unsigned[3]{tri[0], tri[1], tri[2]};
  }

  ExportFailure failure;
  Assimp::Exporter exporter;
  exporter.SetIOHandler(new AtomicExportSystem(failure));  // the exporter owns and deletes it
  if (exporter.Export(scene.get(), format, where) != aiReturn_SUCCESS) {
    throw Error(where, std::string("cannot write mesh: ") + exporter.GetErrorString());
  }
  if (!failure.file.empty()) {
    // An exporter's second file (OBJ's .mtl) is named; the mesh file itself is the `where`.
    throw Error(where, (failure.file == where ? "" : failure.file + ": ") + failure.message);
  }
}

std::optional<double> metres_per_unit(std::string_view unit) {
  std::string u(unit);
  std::transform(u.begin(), u.end(), u.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (u == "m" || u == "metre" || u == "meter" || u == "metres" || u == "meters") {
    return 1.0;
  }
  if (u == "cm") {
    return 1e-2;
  }
  if (u == "mm") {
    return 1e-3;
  }
  if (u == "um" || u == "µm") {
    return 1e-6;
  }
  if (u == "in" || u == "inch") {
    return 0.0254;
  }
  if (u == "ft" || u == "foot" || u == "feet") {
    return 0.3048;
  }
  return std::nullopt;
}

}  // namespace hapsim
