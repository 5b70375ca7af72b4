#include <pointhaptics/reduction/basis_cache.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/core/run_control.hpp>
#include <pointhaptics/io/output_file.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <span>
#include <system_error>
#include <vector>

namespace pointhaptics {
namespace {

// the file: magic, then the header and the numbers in this machine's byte order, then the FNV-1a hash of all the
// bytes between the magic and it. Version 1. The magic is part of the key too: a change of the layout, of what the
// key covers or of how the basis is made (reduction/modal_basis.cpp) must change it, so that no older file is read.
constexpr std::string_view magic = "PHBASIS1";

class Fnv1a {
 public:
  void bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    // a stop honoured between blocks of 16 MB (about 10 ms each): a million points' model is hundreds of MB
    for (std::size_t block = 0; block < n; block += std::size_t{1} << 24) {
      throw_if_stop_requested("reduction cache (the basis' key)");
      const std::size_t end = std::min(n, block + (std::size_t{1} << 24));
      for (std::size_t k = block; k < end; ++k) hash_ = (hash_ ^ p[k]) * 1099511628211ull;
    }
  }
  template <class T>
  void value(const T& v) {
    bytes(&v, sizeof(T));
  }
  template <class T>
  void values(std::span<const T> v) {
    value(static_cast<std::uint64_t>(v.size()));
    bytes(v.data(), v.size_bytes());
  }
  std::uint64_t hash() const { return hash_; }

 private:
  std::uint64_t hash_ = 14695981039346656037ull;
};

template <class Derived>
std::span<const double> doubles(const Eigen::DenseBase<Derived>& m) {
  return {m.derived().data(), static_cast<std::size_t>(m.size())};
}

struct Header {
  std::uint64_t key = 0;
  std::int64_t rows = 0, cols = 0, n_eigenvalues = 0;
  std::int32_t linear_modes = 0, derivatives = 0, load_vectors = 0, unused = 0;
};

}  // namespace

std::uint64_t basis_key(const Model& model, const ModalBasisSettings& settings, double basis_spacing) {
  Fnv1a h;
  h.bytes(magic.data(), magic.size());
  h.value(static_cast<std::int64_t>(model.n_points));
  h.values(doubles(model.X));
  h.values(doubles(model.mass));
  h.values(doubles(model.stiffness_volume));
  h.values(std::span<const index_t>(model.neighbours.offset));
  h.values(std::span<const index_t>(model.neighbours.index));
  h.values(doubles(model.d));
  h.values(doubles(model.d_self));
  h.values(doubles(model.hg_coef));
  h.values(std::span<const unsigned char>(model.fixed));
  h.values(doubles(model.f_ext));
  h.value(model.lambda);
  h.value(model.mu);
  h.value(static_cast<std::int32_t>(model.material.model));
  h.value(static_cast<std::int32_t>(settings.size));
  h.value(static_cast<std::int32_t>(settings.linear_modes));
  h.value(static_cast<std::uint64_t>(settings.loads.size()));
  for (const Points& load : settings.loads) h.values(doubles(load));
  h.value(basis_spacing);
  return h.hash();
}

std::string default_basis_cache_dir() {
  namespace fs = std::filesystem;
  if (const char* dir = std::getenv("POINTHAPTICS_CACHE_DIR"); dir && *dir) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return (fs::path(xdg) / "pointhaptics").string();
  if (const char* home = std::getenv("HOME"); home && *home)
    return (fs::path(home) / ".cache" / "pointhaptics").string();
  return {};
}

std::string basis_cache_file(const std::string& dir, std::uint64_t key) {
  return (std::filesystem::path(dir) / fmt::format("reduction-{:016x}.basis", key)).string();
}

CachedBasis read_basis_cache(const std::string& file, std::uint64_t key, index_t n_points, int size) {
  CachedBasis out;
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) {
    out.missing = true;
    out.why = "no file";
    return out;
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    out.why = "cannot be opened";
    return out;
  }
  const std::vector<char> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const std::size_t expected_doubles =
      static_cast<std::size_t>(3 * n_points) * static_cast<std::size_t>(size);  // U; eigenvalues come on top
  if (bytes.size() < magic.size() + sizeof(Header) + sizeof(std::uint64_t) ||
      std::memcmp(bytes.data(), magic.data(), magic.size()) != 0) {
    out.why = "not a basis file of this version";
    return out;
  }
  Header header;
  std::memcpy(&header, bytes.data() + magic.size(), sizeof(Header));
  if (header.key != key) {
    out.why = "made for another object or settings";
    return out;
  }
  if (header.rows != 3 * static_cast<std::int64_t>(n_points) || header.cols != size || header.n_eigenvalues < 0 ||
      header.n_eigenvalues > 100000) {
    out.why = fmt::format("its basis is {} x {}, not {} x {}", header.rows, header.cols, 3 * n_points, size);
    return out;
  }
  const std::size_t n_doubles = expected_doubles + static_cast<std::size_t>(header.n_eigenvalues);
  const std::size_t body = sizeof(Header) + n_doubles * sizeof(double);
  if (bytes.size() != magic.size() + body + sizeof(std::uint64_t)) {
    out.why = fmt::format("{} bytes, not the {} its header says (truncated?)", bytes.size(),
                          magic.size() + body + sizeof(std::uint64_t));
    return out;
  }
  Fnv1a check;
  check.bytes(bytes.data() + magic.size(), body);
  std::uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + magic.size() + body, sizeof(stored));
  if (stored != check.hash()) {
    out.why = "its checksum does not match (damaged)";
    return out;
  }
  ModalBasis basis;
  const char* numbers = bytes.data() + magic.size() + sizeof(Header);
  basis.eigenvalues.resize(header.n_eigenvalues);
  std::memcpy(basis.eigenvalues.data(), numbers, static_cast<std::size_t>(header.n_eigenvalues) * sizeof(double));
  basis.U.resize(header.rows, header.cols);
  std::memcpy(basis.U.data(), numbers + static_cast<std::size_t>(header.n_eigenvalues) * sizeof(double),
              expected_doubles * sizeof(double));
  if (!basis.U.allFinite() || !basis.eigenvalues.allFinite()) {
    out.why = "holds numbers that are not finite";
    return out;
  }
  basis.linear_modes = header.linear_modes;
  basis.derivatives = header.derivatives;
  basis.load_vectors = header.load_vectors;
  out.basis = std::move(basis);
  return out;
}

void write_basis_cache(const std::string& file, std::uint64_t key, const ModalBasis& basis) {
  namespace fs = std::filesystem;
  const fs::path folder = fs::path(file).parent_path();
  std::error_code ec;
  if (!folder.empty()) fs::create_directories(folder, ec);
  if (ec) throw Error(fmt::format("reduction cache {}: cannot make its folder ({})", file, ec.message()));
  Header header;
  header.key = key;
  header.rows = basis.U.rows();
  header.cols = basis.U.cols();
  header.n_eigenvalues = basis.eigenvalues.size();
  header.linear_modes = basis.linear_modes;
  header.derivatives = basis.derivatives;
  header.load_vectors = basis.load_vectors;
  Fnv1a check;
  auto put = [&](TextOutput& out, const void* data, std::size_t n) {
    out.write(std::string_view(static_cast<const char*>(data), n));
    check.bytes(data, n);
  };
  TextOutput out(file, "reduction cache");
  out.write(magic);
  put(out, &header, sizeof(header));
  put(out, basis.eigenvalues.data(), static_cast<std::size_t>(basis.eigenvalues.size()) * sizeof(double));
  put(out, basis.U.data(), static_cast<std::size_t>(basis.U.size()) * sizeof(double));
  const std::uint64_t sum = check.hash();
  out.write(std::string_view(reinterpret_cast<const char*>(&sum), sizeof(sum)));
  out.commit();
}

}  // namespace pointhaptics
