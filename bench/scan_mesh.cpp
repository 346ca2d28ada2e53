// The streamed scan-like mesh of scan_mesh.h. Each component is a latitude-longitude grid
// of R rings of C = 2R vertices between two poles; a vertex is (ring, column), the poles
// rings -1 and R. Band q holds the faces between rings q and q + 1 (the pole fans are bands
// -1 and R - 1). A vertex is kept when it lies outside every hole and some face of its two
// bands has no vertex in a hole; a face is kept when none of its vertices is in a hole (so
// all of them are kept). Everything is recomputed ring by ring, so the memory is a few rings
// and one prefix count per ring.
#include "scan_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

namespace pomar::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;

uint64_t mix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/// Uniform in [0, 1) from a key.
double unit(uint64_t key) {
  return static_cast<double>(mix(key) >> 11) * (1.0 / 9007199254740992.0);
}

struct Vec3 {
  double x, y, z;
};

double dot(const Vec3 &a, const Vec3 &b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

Vec3 random_direction(uint64_t key) {
  const double z = 2 * unit(key) - 1, phi = 2 * kPi * unit(key + 1);
  const double s = std::sqrt(std::max(0.0, 1 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

struct Corner {
  int ring, column;
};

class Component {
public:
  Component(uint64_t key, uint64_t vertices, double radius, Vec3 center, int holes)
      : key_(key), radius_(radius), center_(center) {
    rings_ =
        std::max(3, static_cast<int>(std::lround(std::sqrt(static_cast<double>(vertices) / 2))));
    columns_ = 2 * rings_;
    for (int o = 0; o < 4; ++o) {
      Bump b;
      b.a = random_direction(mix(key_ * 64 + 2 * o));
      b.b = random_direction(mix(key_ * 64 + 2 * o + 1));
      b.frequency = 3.0 * (1 << o);
      b.amplitude = 0.08 / (1 << o);
      b.phase_a = 2 * kPi * unit(key_ * 64 + 20 + o);
      b.phase_b = 2 * kPi * unit(key_ * 64 + 30 + o);
      bumps_.push_back(b);
    }
    // Caps of about 0.4% of the sphere, at least 2.5 ring steps wide, centred within 30
    // degrees of the equator so that they never reach a pole (the radius is at most 0.5).
    const double alpha =
        std::min(0.5, std::max(std::acos(1 - 2 * 0.004), 2.5 * kPi / (rings_ + 1)));
    for (int h = 0; h < holes; ++h) {
      const double lat = (unit(key_ * 64 + 40 + h) - 0.5) * (kPi / 3);
      // Longitudes spread evenly with some jitter: caps at least 60 degrees apart never meet.
      const double lon = 2 * kPi * (h + 0.5 * unit(key_ * 64 + 50 + h)) / holes;
      hole_centres_.push_back(
          {std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat)});
    }
    hole_cos_ = std::cos(alpha);
    for (int i = 0; i < rings_; ++i) {
      const double theta = kPi * (i + 1) / (rings_ + 1);
      sin_theta_.push_back(std::sin(theta));
      cos_theta_.push_back(std::cos(theta));
    }
    for (int j = 0; j < columns_; ++j) {
      const double phi = 2 * kPi * j / columns_;
      sin_phi_.push_back(std::sin(phi));
      cos_phi_.push_back(std::cos(phi));
    }
  }

  int rings() const { return rings_; }
  int columns(int ring) const { return ring < 0 || ring >= rings_ ? 1 : columns_; }

  Vec3 direction(int ring, int column) const {
    if (ring < 0)
      return {0, 0, 1};
    if (ring >= rings_)
      return {0, 0, -1};
    return {sin_theta_[ring] * cos_phi_[column], sin_theta_[ring] * sin_phi_[column],
            cos_theta_[ring]};
  }

  bool in_hole(int ring, int column) const {
    if (ring < 0 || ring >= rings_)
      return false;
    const Vec3 d = direction(ring, column);
    for (const Vec3 &c : hole_centres_)
      if (dot(d, c) > hole_cos_)
        return true;
    return false;
  }

  Vec3 position(int ring, int column) const {
    const Vec3 d = direction(ring, column);
    double r = 1;
    for (const Bump &b : bumps_)
      r += b.amplitude * std::sin(b.frequency * dot(d, b.a) + b.phase_a) *
           std::cos(b.frequency * dot(d, b.b) + b.phase_b);
    const uint64_t vertex_key =
        (static_cast<uint64_t>(ring + 1) << 32) | static_cast<uint32_t>(column);
    r += 0.001 * (unit(mix(key_) ^ vertex_key) - 0.5);
    r *= radius_;
    return {center_.x + r * d.x, center_.y + r * d.y, center_.z + r * d.z};
  }

  /// Calls f(a, b, c) for every face of band q (-1 .. rings - 1), oriented outwards.
  template <class F> void band_faces(int q, F &&f) const {
    for (int j = 0; j < columns_; ++j) {
      const int jn = (j + 1) % columns_;
      if (q < 0) {
        f(Corner{-1, 0}, Corner{0, j}, Corner{0, jn});
      } else if (q == rings_ - 1) {
        f(Corner{q, j}, Corner{rings_, 0}, Corner{q, jn});
      } else {
        f(Corner{q, j}, Corner{q + 1, j}, Corner{q, jn});
        f(Corner{q, jn}, Corner{q + 1, j}, Corner{q + 1, jn});
      }
    }
  }

  bool face_kept(Corner a, Corner b, Corner c) const {
    return !in_hole(a.ring, a.column) && !in_hole(b.ring, b.column) && !in_hole(c.ring, c.column);
  }

  /// kept[j] for the vertices of one ring.
  void kept_ring(int ring, std::vector<char> &kept) const {
    kept.assign(columns(ring), 0);
    auto mark = [&](Corner a, Corner b, Corner c) {
      if (!face_kept(a, b, c))
        return;
      for (const Corner &v : {a, b, c})
        if (v.ring == ring)
          kept[v.column] = 1;
    };
    band_faces(ring - 1, mark);
    band_faces(ring, mark);
  }

private:
  struct Bump {
    Vec3 a, b;
    double frequency, amplitude, phase_a, phase_b;
  };
  uint64_t key_;
  double radius_;
  Vec3 center_;
  int rings_ = 0, columns_ = 0;
  std::vector<Bump> bumps_;
  std::vector<Vec3> hole_centres_;
  double hole_cos_ = 1;
  std::vector<double> sin_theta_, cos_theta_, sin_phi_, cos_phi_; // one per ring, per column
};

std::vector<Component> make_components(const ScanMeshOptions &options) {
  const int k = std::clamp(options.components, 1, 16);
  std::vector<double> weight(k);
  double total = 0;
  for (int i = 0; i < k; ++i)
    total += weight[i] = std::pow(i + 1.0, -1.2);
  std::vector<Component> out;
  double x = 0, previous_radius = 0;
  for (int i = 0; i < k; ++i) {
    const double share = weight[i] / total;
    const double radius = std::sqrt(share); // about the same sampling density everywhere
    x += (i == 0 ? 0 : previous_radius + 1.3 * radius);
    const Vec3 center = {x, 0.2 * radius * std::sin(i + 1.0), 0.1 * radius * std::cos(3.0 * i)};
    const int holes = i == k - 1 && k > 1 ? 0 : (i == 0 ? 3 : 1);
    const uint64_t vertices =
        std::max<uint64_t>(20, static_cast<uint64_t>(share * options.vertices));
    out.emplace_back(mix((static_cast<uint64_t>(options.seed) << 8) | static_cast<uint64_t>(i)),
                     vertices, radius, center, holes);
    previous_radius = radius;
  }
  return out;
}

/// Kept-vertex numbers of one ring: index[j] (UINT32_MAX if not kept), counting from `first`.
uint64_t number_ring(const Component &c, int ring, uint64_t first, std::vector<char> &kept,
                     std::vector<uint32_t> &index) {
  c.kept_ring(ring, kept);
  index.assign(kept.size(), UINT32_MAX);
  for (size_t j = 0; j < kept.size(); ++j)
    if (kept[j])
      index[j] = static_cast<uint32_t>(first++);
  return first;
}

class Writer {
public:
  explicit Writer(std::FILE *file) : file_(file) { buffer_.reserve(kChunk + 64); }
  void bytes(const void *p, size_t n) {
    const auto *b = static_cast<const unsigned char *>(p);
    buffer_.insert(buffer_.end(), b, b + n);
    if (buffer_.size() >= kChunk)
      flush();
  }
  void u8(uint8_t v) { bytes(&v, 1); }
  void u32(uint32_t v) {
    const unsigned char b[4] = {static_cast<unsigned char>(v), static_cast<unsigned char>(v >> 8),
                                static_cast<unsigned char>(v >> 16),
                                static_cast<unsigned char>(v >> 24)};
    bytes(b, 4);
  }
  void f32(float f) {
    uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    u32(bits);
  }
  void flush() {
    if (!buffer_.empty() && std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size())
      ok_ = false;
    buffer_.clear();
  }
  bool ok() const { return ok_; }

private:
  static constexpr size_t kChunk = 1 << 20;
  std::FILE *file_;
  std::vector<unsigned char> buffer_;
  bool ok_ = true;
};

} // namespace

ScanMeshCounts count_scan_mesh(const ScanMeshOptions &options) {
  ScanMeshCounts counts;
  std::vector<char> kept;
  for (const Component &c : make_components(options)) {
    for (int ring = -1; ring <= c.rings(); ++ring) {
      c.kept_ring(ring, kept);
      counts.vertices += static_cast<uint64_t>(std::count(kept.begin(), kept.end(), 1));
    }
    for (int q = -1; q < c.rings(); ++q)
      c.band_faces(
          q, [&](Corner a, Corner b, Corner d) { counts.faces += c.face_kept(a, b, d) ? 1 : 0; });
  }
  return counts;
}

bool write_scan_ply(const ScanMeshOptions &options, const std::string &path, ScanMeshCounts &counts,
                    std::string &error) {
  counts = count_scan_mesh(options);
  if (counts.vertices >= UINT32_MAX) {
    error = "more than 2^32 - 1 vertices";
    return false;
  }
  std::unique_ptr<std::FILE, int (*)(std::FILE *)> file(std::fopen(path.c_str(), "wb"),
                                                        std::fclose);
  if (!file) {
    error = "cannot open '" + path + "' for writing";
    return false;
  }
  const std::string header = "ply\nformat binary_little_endian 1.0\n"
                             "comment generated by pomar_gen_mesh scan\n"
                             "element vertex " +
                             std::to_string(counts.vertices) +
                             "\n"
                             "property float x\nproperty float y\nproperty float z\n"
                             "element face " +
                             std::to_string(counts.faces) +
                             "\n"
                             "property list uchar uint vertex_indices\nend_header\n";
  Writer out(file.get());
  out.bytes(header.data(), header.size());
  const std::vector<Component> components = make_components(options);
  std::vector<char> kept;
  std::vector<uint32_t> index;
  for (const Component &c : components)
    for (int ring = -1; ring <= c.rings(); ++ring) {
      c.kept_ring(ring, kept);
      for (int j = 0; j < c.columns(ring); ++j)
        if (kept[j]) {
          const Vec3 p = c.position(ring, j);
          out.f32(static_cast<float>(p.x));
          out.f32(static_cast<float>(p.y));
          out.f32(static_cast<float>(p.z));
        }
    }
  uint64_t first = 0;
  std::vector<uint32_t> upper, lower;
  std::vector<char> kept_lower;
  for (const Component &c : components) {
    // Rings q and q + 1 numbered, band q written, the lower ring kept for the next band.
    first = number_ring(c, -1, first, kept, upper);
    for (int q = -1; q < c.rings(); ++q) {
      first = number_ring(c, q + 1, first, kept_lower, lower);
      auto number = [&](Corner v) { return v.ring == q ? upper[v.column] : lower[v.column]; };
      c.band_faces(q, [&](Corner a, Corner b, Corner d) {
        if (!c.face_kept(a, b, d))
          return;
        out.u8(3);
        out.u32(number(a));
        out.u32(number(b));
        out.u32(number(d));
      });
      upper.swap(lower);
    }
  }
  out.flush();
  if (first != counts.vertices)
    error = "internal: numbered " + std::to_string(first) + " vertices, counted " +
            std::to_string(counts.vertices);
  if (!out.ok())
    error = "cannot write '" + path + "'";
  const int closed = std::fclose(file.release());
  if (closed != 0 && error.empty())
    error = "cannot write '" + path + "'";
  return error.empty();
}

} // namespace pomar::bench
