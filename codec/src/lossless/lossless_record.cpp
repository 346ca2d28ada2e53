// The lossless record's coding (layout: docs/format.md, "LSLS section").
//
// One flags byte, then one range-coded stream: the six counts, then each part in the
// order the decoder meets it. Index lists are coded as gaps (a run of neighbouring flipped
// faces costs almost nothing), numbers as a magnitude class (adaptive) plus the bits below
// the leading one (the first of them adaptive, the others raw).
#include "lossless/lossless_record.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <tuple>

#include "attributes/vertex_rows.h"
#include "entropy/models.h"
#include "entropy/range_coder.h"
#include "memory/prefault.h"
#include "mesh/corner_table.h"
#include "mesh/radix_sort.h"

namespace pomar {

namespace {

constexpr uint8_t kHasOrder = 1;
constexpr uint8_t kHasAttributes = 2; // the extra vertices' attributes end the stream
constexpr int kUintClasses = 34;      // bit lengths 0..33

/// An unsigned number as its bit length (adaptive) and the bits below the leading one.
struct UintModel {
  FrequencyModel classes{kUintClasses};
  BitModel top[kUintClasses];
};

void put_u(RangeEncoder &rc, UintModel &m, uint64_t v) {
  const int n = bit_length(v);
  rc.encode(m.classes, n);
  if (n < 2)
    return;
  int rest = n - 1;
  rc.encode_bit(m.top[n], static_cast<int>((v >> (rest - 1)) & 1));
  --rest;
  put_raw(rc, v & ((uint64_t(1) << rest) - 1), rest);
}

uint64_t get_u(RangeDecoder &rc, UintModel &m) {
  const int n = rc.decode(m.classes);
  if (n < 2)
    return static_cast<uint64_t>(n);
  int rest = n - 1;
  uint64_t v = 2 | static_cast<uint64_t>(rc.decode_bit(m.top[n]));
  --rest;
  return (v << rest) | get_raw(rc, rest);
}

/// Position groups: group[v] numbers the distinct positions of `mesh` (exact float bits)
/// in the order of their bits (x, y, z as unsigned words). Two stable radix sorts, by z and
/// then by (x, y): linear (a comparison sort of the vertices through their positions takes
/// a twentieth of a messy mesh's decode).
std::vector<uint32_t> position_groups(const Mesh &mesh) {
  const uint32_t n = static_cast<uint32_t>(mesh.vertex_count());
  const auto word = [&](uint32_t v, int k) {
    uint32_t w;
    std::memcpy(&w, &mesh.positions[3 * size_t(v) + k], sizeof w);
    return w;
  };
  std::vector<Keyed> by(n);
  for (uint32_t v = 0; v < n; ++v)
    by[v] = {word(v, 2), v};
  sort_by_key(by); // by z
  for (Keyed &e : by)
    e.key = uint64_t(word(e.id, 0)) << 32 | word(e.id, 1);
  sort_by_key(by); // by (x, y), stable: by (x, y, z)
  std::vector<uint32_t> group(n);
  uint32_t g = 0;
  for (uint32_t i = 0; i < n; ++i) {
    if (i > 0 && (by[i].key != by[i - 1].key || word(by[i].id, 2) != word(by[i - 1].id, 2)))
      ++g;
    group[by[i].id] = g;
  }
  return group;
}

/// The representatives met so far per position group (decoded vertices that are not
/// copies), in decoding order: the candidates of a copy.
struct Candidates {
  std::vector<uint32_t> group, head, tail, count, next;
  explicit Candidates(const Mesh &mesh) : group(position_groups(mesh)) {
    const size_t n = group.size();
    head.assign(n, kNoVertex);
    tail.assign(n, kNoVertex);
    count.assign(n, 0);
    next.assign(n, kNoVertex);
  }
  static constexpr uint32_t kNoVertex = 0xFFFFFFFFu;
  void add(uint32_t v) {
    const uint32_t g = group[v];
    if (tail[g] == kNoVertex)
      head[g] = v;
    else
      next[tail[g]] = v;
    tail[g] = v;
    ++count[g];
  }
  uint32_t of(uint32_t v) const { return count[group[v]]; }
  uint32_t nth(uint32_t v, uint32_t k) const {
    uint32_t c = head[group[v]];
    while (k--)
      c = next[c];
    return c;
  }
  uint32_t index_of(uint32_t v, uint32_t rep) const {
    uint32_t k = 0;
    for (uint32_t c = head[group[v]]; c != kNoVertex; c = next[c], ++k)
      if (c == rep)
        return k;
    return kNoVertex;
  }
};

/// All the adaptive models of a record.
struct RecordModels {
  UintModel counts, copy_gap, copy_index, flip_gap, dup_gap, dup_count, degen_gap, degen_b,
      extra[3], order_symbol;
  BitModel degen_single, extra_sign[3]; // sorted extra vertices: x rarely goes down
};

[[noreturn]] void damaged(const std::string &what) {
  throw Error(Error::Kind::DamagedFile, "damaged .pomar file: lossless record: " + what);
}

/// Upper bound for a count read from a body of `size` bytes (an adaptive model can make a
/// symbol cost very little, but not nothing): refuses absurd counts before allocating.
uint64_t count_bound(size_t size) { return 16384 * uint64_t(size) + 1024; }

LosslessCounts counts_of(const LosslessRecord &r) {
  LosslessCounts n;
  n.copies = r.copies.size();
  n.flipped = r.flipped.size();
  n.duplicated = r.duplicates.size();
  for (const auto &d : r.duplicates)
    n.duplicate_faces += d.second;
  n.degenerate = r.degenerate.size();
  n.extra = r.extra_q.size() / 3;
  n.order = !r.order.empty();
  return n;
}

/// The flags byte and the counts; leaves `rc` and `m` ready for the parts.
LosslessCounts read_counts(const uint8_t *data, size_t size, RangeDecoder &rc, RecordModels &m) {
  if (size < 1)
    damaged("empty");
  if (data[0] & ~(kHasOrder | kHasAttributes))
    damaged("unknown flags " + std::to_string(data[0]));
  rc.reset(data + 1, size - 1);
  LosslessCounts n;
  n.order = (data[0] & kHasOrder) != 0;
  n.copies = get_u(rc, m.counts);
  n.flipped = get_u(rc, m.counts);
  n.duplicated = get_u(rc, m.counts);
  n.duplicate_faces = get_u(rc, m.counts);
  n.degenerate = get_u(rc, m.counts);
  n.extra = get_u(rc, m.counts);
  const uint64_t bound = count_bound(size);
  if (n.copies > 0xFFFFFFFFu || n.flipped > 0xFFFFFFFFu || n.duplicated > n.duplicate_faces ||
      n.duplicate_faces > bound || n.degenerate > bound || n.extra > bound)
    damaged("counts are larger than the record can hold");
  return n;
}

/// A value in [0, total) as equally likely: up to 2^16 values in one step, else the high
/// part (up to 2^16 values) then the low bits raw.
void put_uniform(RangeEncoder &rc, uint32_t v, uint32_t total) {
  const int shift = std::max(0, bit_length(total - 1) - 16);
  rc.encode_uniform(v >> shift, ((total - 1) >> shift) + 1);
  if (shift)
    rc.encode_bypass(v & ((1u << shift) - 1), shift);
}

uint32_t get_uniform(RangeDecoder &rc, uint32_t total) {
  const int shift = std::max(0, bit_length(total - 1) - 16);
  uint32_t v = rc.decode_uniform(((total - 1) >> shift) + 1) << shift;
  if (shift)
    v |= rc.decode_bypass(shift);
  return v;
}

/// Which of 0..n-1 are still unused, with rank queries (Fenwick tree of counts).
class UnusedSet {
public:
  explicit UnusedSet(uint32_t n) : tree_(n + 1, 0), left_(n) {
    for (uint32_t i = 1; i <= n; ++i) {
      tree_[i] += 1;
      const uint32_t j = i + (i & (0u - i));
      if (j <= n)
        tree_[j] += tree_[i];
    }
  }
  uint32_t left() const { return left_; }
  /// Unused items below v.
  uint32_t rank(uint32_t v) const {
    uint32_t s = 0;
    for (; v > 0; v -= v & (0u - v))
      s += tree_[v];
    return s;
  }
  /// The unused item of rank k (k < left()).
  uint32_t nth(uint32_t k) const {
    uint32_t pos = 0;
    for (uint32_t step = highest(); step; step >>= 1)
      if (pos + step < tree_.size() && tree_[pos + step] <= k) {
        pos += step;
        k -= tree_[pos];
      }
    return pos;
  }
  bool used(uint32_t v) const { return rank(v + 1) == rank(v); }
  void take(uint32_t v) {
    for (uint32_t i = v + 1; i < tree_.size(); i += i & (0u - i))
      --tree_[i];
    --left_;
  }

private:
  uint32_t highest() const {
    uint32_t h = 1;
    while (2 * h < tree_.size())
      h *= 2;
    return h;
  }
  std::vector<uint32_t> tree_;
  uint32_t left_;
};

/// Vertex neighbours of a triangle list over n vertices: list[start[v] .. end[v]), sorted.
struct Neighbours {
  std::vector<uint32_t> start, end, list;
  Neighbours(const std::vector<uint32_t> &t, uint32_t n) : start(n + 1, 0), end(n) {
    for (size_t c = 0; c < t.size(); ++c)
      start[t[c] + 1] += 2;
    for (uint32_t v = 0; v < n; ++v)
      start[v + 1] += start[v];
    list.resize(start[n]);
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (size_t f = 0; f < t.size() / 3; ++f)
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = t[3 * f + k];
        list[fill[v]++] = t[3 * f + (k + 1) % 3];
        list[fill[v]++] = t[3 * f + (k + 2) % 3];
      }
    for (uint32_t v = 0; v < n; ++v) {
      auto b = list.begin() + start[v], e = list.begin() + start[v + 1];
      std::sort(b, e);
      end[v] = start[v] + static_cast<uint32_t>(std::unique(b, e) - b);
    }
  }
};

/// Candidates for the output vertex of the next input vertex, after `prev`'s: the next
/// unused output vertex after prev (symbol 1), then prev's unused neighbours (2, 3, ...);
/// symbol 0 is "none of them" (then the rank among all unused vertices follows).
template <class Visit>
void order_candidates(const Neighbours &nb, const UnusedSet &unused, uint32_t prev, Visit visit) {
  uint32_t symbol = 1;
  const uint32_t r = unused.rank(prev + 1);
  uint32_t following = r < unused.left() ? unused.nth(r) : kNone;
  if (following != kNone && visit(following, symbol++))
    return;
  for (uint32_t i = nb.start[prev]; i < nb.end[prev]; ++i) {
    const uint32_t w = nb.list[i];
    if (w == following || unused.used(w))
      continue;
    if (visit(w, symbol++))
      return;
  }
}

} // namespace

LosslessCounts read_lossless_counts(const uint8_t *data, size_t size) {
  RangeDecoder rc;
  RecordModels m;
  return read_counts(data, size, rc, m);
}

namespace {

/// The rotation of face f of `t` that starts at its smallest vertex (the first of them if
/// it repeats one): k = (v[s], v[s+1], v[s+2]); returns s.
int rotated(const uint32_t *t, uint32_t f, uint32_t k[3]) {
  const uint32_t *v = &t[3 * size_t(f)];
  const int s = v[0] < v[1] ? (v[0] < v[2] ? 0 : 2) : (v[1] < v[2] ? 1 : 2);
  k[0] = v[s], k[1] = v[(s + 1) % 3], k[2] = v[(s + 2) % 3];
  return s;
}

/// Whether canonical_buckets takes `t` (ids up to `top`): ids about as many as the faces (a
/// mesh's own), fewer than 2^30 faces.
bool dense_ids(const std::vector<uint32_t> &t, uint32_t top) {
  const uint64_t nf = t.size() / 3;
  return top < 4 * nf + 1024 && nf < (uint64_t(1) << 30);
}

/// The canonical order as buckets: the faces counted by smallest vertex k0 (a counting
/// sort, faces in index order, so stable), then each bucket, a few faces, sorted by the
/// rest. by[i] = (k1 << 32 | k2, f << 2 | s) for the i-th face f in canonical order, s its
/// rotation (rotated()); bucket k0 ends at end[k0].
void canonical_buckets(const std::vector<uint32_t> &t, uint32_t top, std::vector<uint32_t> &end,
                       std::vector<Keyed> &by) {
  const uint32_t nf = static_cast<uint32_t>(t.size() / 3);
  end.assign(size_t(top) + 2, 0);
  for (uint32_t f = 0; f < nf; ++f) {
    const uint32_t *v = &t[3 * size_t(f)];
    ++end[std::min(v[0], std::min(v[1], v[2])) + 1];
  }
  for (size_t v = 0; v + 1 < end.size(); ++v)
    end[v + 1] += end[v];
  by = filled_vector<Keyed>(nf); // (memory/prefault.h)
  for (uint32_t f = 0; f < nf; ++f) {
    uint32_t k[3];
    const int s = rotated(t.data(), f, k);
    by[end[k[0]]++] = {uint64_t(k[1]) << 32 | k[2], f << 2 | uint32_t(s)};
  }
  // (end[v] is now the end of bucket v.)
  const auto less = [](const Keyed &a, const Keyed &b) {
    return a.key != b.key ? a.key < b.key : a.id < b.id;
  };
  for (size_t v = 0, first = 0; v <= top; first = end[v++]) {
    Keyed *b = by.data() + first, *e = by.data() + end[v];
    if (e - b > 16) {
      std::sort(b, e, less);
      continue;
    }
    for (Keyed *i = b + 1; i < e; ++i) // insertion sort by key, stable: faces stay in order
      for (Keyed *j = i; j > b && j[-1].key > j->key; --j)
        std::swap(j[-1], j[0]);
  }
}

} // namespace

std::vector<uint32_t> canonical_face_order(const std::vector<uint32_t> &t) {
  // Each face's vertices rotated to start at the smallest; the faces sorted by that triple,
  // equal triples (duplicate faces) by face index. Ids up to a few times the face count (a
  // mesh's own, every caller's): bucketed by the smallest vertex, the buckets sorted (a
  // comparison sort of indices through the triples takes a sixth of a 35k-vertex decode's
  // CPU time). Sparse ids (only a test makes them) sort the triples themselves.
  const uint32_t nf = static_cast<uint32_t>(t.size() / 3);
  const uint32_t top = t.empty() ? 0 : *std::max_element(t.begin(), t.end());
  std::vector<uint32_t> order = filled_vector<uint32_t>(nf); // (memory/prefault.h)
  if (dense_ids(t, top)) {
    std::vector<uint32_t> end;
    std::vector<Keyed> by;
    canonical_buckets(t, top, end, by);
    for (uint32_t i = 0; i < nf; ++i)
      order[i] = by[i].id >> 2;
    return order;
  }
  struct Face {
    uint32_t k[3], f;
  };
  std::vector<Face> faces(nf);
  for (uint32_t f = 0; f < nf; ++f) {
    rotated(t.data(), f, faces[f].k);
    faces[f].f = f;
  }
  std::sort(faces.begin(), faces.end(), [](const Face &a, const Face &b) {
    return std::tie(a.k[0], a.k[1], a.k[2], a.f) < std::tie(b.k[0], b.k[1], b.k[2], b.f);
  });
  for (uint32_t i = 0; i < nf; ++i)
    order[i] = faces[i].f;
  return order;
}

/// The extra vertices' attributes, raw: a count, then per attribute its kind, components
/// and name, then its values (colour bytes as 8 bits, floats as their 32 bits, high half
/// first), all as equiprobable bits.
void write_extra_attributes(RangeEncoder &rc, const std::vector<VertexAttribute> &attributes) {
  if (attributes.empty())
    return;
  rc.encode_bypass(static_cast<uint32_t>(attributes.size()), 8);
  for (const VertexAttribute &a : attributes) {
    rc.encode_bypass(static_cast<uint32_t>(a.kind), 8);
    rc.encode_bypass(a.components, 8);
    rc.encode_bypass(static_cast<uint32_t>(a.name.size()), 8);
    for (char c : a.name)
      rc.encode_bypass(static_cast<uint8_t>(c), 8);
  }
  for (const VertexAttribute &a : attributes) {
    for (uint8_t c : a.colour)
      rc.encode_bypass(c, 8);
    for (float f : a.values) {
      uint32_t bits;
      std::memcpy(&bits, &f, 4);
      rc.encode_bypass(bits >> 16, 16);
      rc.encode_bypass(bits & 0xFFFF, 16);
    }
  }
}

std::vector<VertexAttribute> read_extra_attributes(RangeDecoder &rc, uint64_t extra, size_t size) {
  const uint32_t count = rc.decode_bypass(8);
  if (count == 0)
    damaged("attribute flag without attributes");
  std::vector<VertexAttribute> out(count);
  for (VertexAttribute &a : out) {
    const uint32_t kind = rc.decode_bypass(8);
    if (kind < 1 || kind > 4)
      damaged("unknown attribute kind " + std::to_string(kind));
    a.kind = static_cast<AttributeKind>(kind);
    a.components = rc.decode_bypass(8);
    if (a.components < 1 || a.components > 4)
      damaged("attribute with " + std::to_string(a.components) + " components");
    const uint32_t length = rc.decode_bypass(8);
    if (length == 0)
      damaged("attribute without a name");
    for (uint32_t i = 0; i < length; ++i)
      a.name += static_cast<char>(rc.decode_bypass(8));
  }
  for (VertexAttribute &a : out) {
    // Every value takes at least a byte of the record: refuse counts the data cannot hold
    // before allocating for them.
    const uint64_t values = extra * a.components;
    if (values > size)
      damaged("more attribute values than the record holds");
    if (a.kind == AttributeKind::Colour) {
      a.colour.resize(values);
      for (uint8_t &c : a.colour)
        c = static_cast<uint8_t>(rc.decode_bypass(8));
    } else {
      a.values.resize(values);
      for (float &f : a.values) {
        const uint32_t high = rc.decode_bypass(16);
        const uint32_t bits = (high << 16) | rc.decode_bypass(16);
        std::memcpy(&f, &bits, 4);
      }
    }
    if (rc.overrun())
      damaged("the attributes of unreferenced vertices end too early");
  }
  return out;
}

std::vector<uint8_t> write_lossless_record(const LosslessRecord &r, Mesh &&decoded) {
  std::vector<uint8_t> out;
  out.push_back(uint8_t((r.order.empty() ? 0 : kHasOrder) |
                        (r.extra_attributes.empty() ? 0 : kHasAttributes)));
  RangeEncoder rc(&out);
  RecordModels m;
  const LosslessCounts n = counts_of(r);
  put_u(rc, m.counts, n.copies);
  put_u(rc, m.counts, n.flipped);
  put_u(rc, m.counts, n.duplicated);
  put_u(rc, m.counts, n.duplicate_faces);
  put_u(rc, m.counts, n.degenerate);
  put_u(rc, m.counts, n.extra);

  // Copies: a gap over the vertices whose position repeats a representative's, then which
  // representative (only when there are several).
  if (!r.copies.empty()) {
    Candidates cand(decoded);
    size_t next = 0, position = 0, last = 0;
    for (uint32_t v = 0; v < decoded.vertex_count(); ++v) {
      const uint32_t k = cand.of(v);
      if (k == 0) {
        cand.add(v);
        continue;
      }
      if (next < r.copies.size() && r.copies[next].first == v) {
        const uint32_t i = cand.index_of(v, r.copies[next].second);
        if (i == Candidates::kNoVertex)
          throw Error(Error::Kind::Internal,
                      "internal lossless error: a vertex copy is not at its original's position");
        put_u(rc, m.copy_gap, position - last);
        if (k > 1)
          put_u(rc, m.copy_index, i);
        last = position + 1;
        ++next;
      } else {
        cand.add(v);
      }
      ++position;
    }
    if (next != r.copies.size())
      throw Error(Error::Kind::Internal, "internal lossless error: vertex copies out of order");
  }
  uint64_t last = 0;
  for (uint32_t f : r.flipped) {
    put_u(rc, m.flip_gap, f - last);
    last = uint64_t(f) + 1;
  }
  last = 0;
  for (const auto &d : r.duplicates) {
    put_u(rc, m.dup_gap, d.first - last);
    put_u(rc, m.dup_count, d.second - 1);
    last = uint64_t(d.first) + 1;
  }
  last = 0;
  for (const auto &d : r.degenerate) {
    put_u(rc, m.degen_gap, d[0] - last);
    last = d[0];
    rc.encode_bit(m.degen_single, d[0] == d[1]);
    if (d[0] != d[1])
      put_u(rc, m.degen_b, d[1]);
  }
  int32_t prev[3] = {0, 0, 0};
  for (size_t i = 0; i < r.extra_q.size(); ++i) {
    const int k = static_cast<int>(i % 3);
    const int64_t d = int64_t(r.extra_q[i]) - prev[k];
    put_u(rc, m.extra[k], static_cast<uint64_t>(d < 0 ? -d : d));
    if (d != 0)
      rc.encode_bit(m.extra_sign[k], d < 0);
    prev[k] = r.extra_q[i];
  }
  if (!r.order.empty()) {
    LosslessRecord without = r;
    without.order.clear();
    const Mesh mesh = apply_lossless_record(std::move(decoded), without, Quantizer());
    const uint32_t n = static_cast<uint32_t>(mesh.vertex_count());
    if (r.order.size() != n)
      throw Error(Error::Kind::Internal,
                  "internal lossless error: the vertex order does not fit the mesh");
    std::vector<uint32_t> output_of(n);
    for (uint32_t o = 0; o < n; ++o)
      output_of[r.order[o]] = o;
    const Neighbours nb(mesh.triangles, n);
    UnusedSet unused(n);
    for (uint32_t i = 0, prev = 0; i < n; ++i) {
      const uint32_t o = output_of[i];
      uint32_t symbol = 0;
      if (i > 0) {
        order_candidates(nb, unused, prev, [&](uint32_t w, uint32_t s) {
          if (w != o)
            return false;
          symbol = s;
          return true;
        });
        put_u(rc, m.order_symbol, symbol);
      }
      if (symbol == 0)
        put_uniform(rc, unused.rank(o), unused.left());
      unused.take(o);
      prev = o;
    }
  }
  write_extra_attributes(rc, r.extra_attributes);
  rc.finish();
  return out;
}

namespace {

using IndexPairs = std::vector<std::pair<uint32_t, uint32_t>>;

/// The record's header (the flags byte and the counts), checked against D.
LosslessCounts read_header(const uint8_t *data, size_t size, const Mesh &decoded, RangeDecoder &rc,
                           RecordModels &m) {
  const LosslessCounts n = read_counts(data, size, rc, m);
  const uint64_t nv = decoded.vertex_count(), nf = decoded.triangle_count();
  if (n.copies >= std::max<uint64_t>(nv, 1) || n.flipped > nf || n.duplicated > nf)
    damaged("counts do not fit the decoded mesh");
  if (n.vertices(nv) > 0xFFFFFFFEu || n.faces(nf) > 0xFFFFFFFEu)
    damaged("counts are larger than the record can hold");
  return n;
}

/// The vertex copies: a gap over the vertices whose position repeats a representative's,
/// then which representative (only when there are several).
IndexPairs read_copies(RangeDecoder &rc, RecordModels &m, const Mesh &decoded, uint64_t copies) {
  IndexPairs out;
  if (copies == 0)
    return out;
  const uint64_t nv = decoded.vertex_count();
  Candidates cand(decoded);
  out.reserve(copies);
  uint64_t gap = get_u(rc, m.copy_gap);
  for (uint32_t v = 0; v < nv; ++v) {
    const uint32_t k = cand.of(v);
    if (k == 0 || out.size() == copies) {
      cand.add(v);
      continue;
    }
    if (gap > 0) {
      --gap;
      cand.add(v);
      continue;
    }
    const uint64_t i = k > 1 ? get_u(rc, m.copy_index) : 0;
    if (i >= k)
      damaged("vertex " + std::to_string(v) + " is a copy of a vertex that does not exist");
    out.push_back({v, cand.nth(v, static_cast<uint32_t>(i))});
    if (out.size() < copies)
      gap = get_u(rc, m.copy_gap);
  }
  if (out.size() != copies)
    damaged("vertex copies past the last decoded vertex");
  return out;
}

/// The flipped faces of D (of `nf`): gaps between their canonical indices.
std::vector<uint32_t> read_flips(RangeDecoder &rc, RecordModels &m, uint64_t flipped, uint64_t nf) {
  std::vector<uint32_t> out;
  out.reserve(flipped);
  uint64_t at = 0;
  for (uint64_t i = 0; i < flipped; ++i) {
    at += get_u(rc, m.flip_gap);
    if (at >= nf)
      damaged("flipped face past the last face");
    out.push_back(static_cast<uint32_t>(at++));
  }
  return out;
}

/// The duplicated faces of D (of `nf`): per face a gap, then its number of extra copies.
IndexPairs read_duplicates(RangeDecoder &rc, RecordModels &m, const LosslessCounts &n,
                           uint64_t nf) {
  IndexPairs out;
  out.reserve(n.duplicated);
  uint64_t at = 0, copies_of_faces = 0;
  for (uint64_t i = 0; i < n.duplicated; ++i) {
    at += get_u(rc, m.dup_gap);
    const uint64_t k = get_u(rc, m.dup_count) + 1;
    copies_of_faces += k;
    if (at >= nf)
      damaged("duplicated face past the last face");
    if (copies_of_faces > n.duplicate_faces)
      damaged("more duplicate faces than counted");
    out.push_back({static_cast<uint32_t>(at++), static_cast<uint32_t>(k)});
  }
  if (copies_of_faces != n.duplicate_faces)
    damaged("fewer duplicate faces than counted");
  return out;
}

/// The degenerate faces (a, a, b) over `out_vertices` output vertices: a as a gap, then b
/// (a bit when b == a).
std::vector<std::array<uint32_t, 2>> read_degenerate(RangeDecoder &rc, RecordModels &m,
                                                     uint64_t degenerate, uint64_t out_vertices) {
  std::vector<std::array<uint32_t, 2>> out;
  out.reserve(degenerate);
  uint64_t at = 0;
  for (uint64_t i = 0; i < degenerate; ++i) {
    at += get_u(rc, m.degen_gap);
    const uint64_t b = rc.decode_bit(m.degen_single) ? at : get_u(rc, m.degen_b);
    if (at >= out_vertices || b >= out_vertices)
      damaged("degenerate face uses a vertex past the last one");
    out.push_back({static_cast<uint32_t>(at), static_cast<uint32_t>(b)});
  }
  return out;
}

/// The extra vertices' quantized positions: per coordinate, a signed difference from the
/// previous vertex's, on a grid of `bits` bits.
std::vector<int32_t> read_extra_positions(RangeDecoder &rc, RecordModels &m, uint64_t extra,
                                          int bits) {
  const int64_t top = (int64_t(1) << bits) - 1;
  int64_t prev[3] = {0, 0, 0};
  std::vector<int32_t> out;
  out.reserve(3 * extra);
  for (uint64_t i = 0; i < 3 * extra; ++i) {
    const int k = static_cast<int>(i % 3);
    int64_t d = static_cast<int64_t>(get_u(rc, m.extra[k]));
    if (d != 0 && rc.decode_bit(m.extra_sign[k]))
      d = -d;
    const int64_t q = prev[k] + d;
    if (q < 0 || q > top)
      damaged("vertex position off the grid");
    out.push_back(static_cast<int32_t>(q));
    prev[k] = q;
  }
  return out;
}

/// The input vertex numbering, coded against the output's faces (D with `r`, read so far
/// and without an order, undone): its shape only (the attributes of the extra vertices
/// come after the order).
std::vector<uint32_t> read_order(RangeDecoder &rc, RecordModels &m, const Mesh &decoded,
                                 const LosslessRecord &r) {
  Mesh shape;
  shape.positions = decoded.positions;
  shape.triangles = decoded.triangles;
  const Mesh mesh = apply_lossless_record(std::move(shape), r, Quantizer());
  const uint32_t n = static_cast<uint32_t>(mesh.vertex_count());
  const Neighbours nb(mesh.triangles, n);
  UnusedSet unused(n);
  std::vector<uint32_t> order(n);
  for (uint32_t i = 0, prev = 0; i < n; ++i) {
    const uint64_t symbol = i > 0 ? get_u(rc, m.order_symbol) : 0;
    uint32_t o = kNone;
    if (symbol == 0) {
      const uint32_t k = get_uniform(rc, unused.left());
      if (k >= unused.left())
        damaged("vertex order: rank past the last vertex");
      o = unused.nth(k);
    } else {
      order_candidates(nb, unused, prev, [&](uint32_t w, uint32_t s) {
        if (s != symbol)
          return false;
        o = w;
        return true;
      });
      if (o == kNone)
        damaged("vertex order: input vertex " + std::to_string(i) + " has no output vertex");
    }
    order[o] = i;
    unused.take(o);
    prev = o;
  }
  return order;
}

} // namespace

LosslessRecord read_lossless_record(const uint8_t *data, size_t size, const Mesh &decoded,
                                    int bits) {
  RangeDecoder rc;
  RecordModels m;
  const LosslessCounts n = read_header(data, size, decoded, rc, m);
  const uint64_t nv = decoded.vertex_count(), nf = decoded.triangle_count();
  LosslessRecord r;
  r.copies = read_copies(rc, m, decoded, n.copies);
  r.flipped = read_flips(rc, m, n.flipped, nf);
  r.duplicates = read_duplicates(rc, m, n, nf);
  r.degenerate = read_degenerate(rc, m, n.degenerate, nv - n.copies + n.extra);
  r.extra_q = read_extra_positions(rc, m, n.extra, bits);
  if (data[0] & kHasOrder)
    r.order = read_order(rc, m, decoded, r);
  if (data[0] & kHasAttributes)
    r.extra_attributes = read_extra_attributes(rc, n.extra, size);
  if (rc.overrun())
    damaged("the data ends too early");
  return r;
}

namespace {

/// Per attribute of D, the extra vertices' values of it (none: a record without
/// attributes, e.g. written for a mesh that had none); checks that the record fits D.
std::vector<const VertexAttribute *> check_record_fits(const Mesh &decoded,
                                                       const LosslessRecord &r) {
  const uint32_t nv = static_cast<uint32_t>(decoded.vertex_count());
  const size_t extra = r.extra_q.size() / 3;
  std::vector<const VertexAttribute *> extra_of;
  for (const VertexAttribute &a : decoded.attributes) {
    const VertexAttribute *x = nullptr;
    for (const VertexAttribute &e : r.extra_attributes)
      if (e.kind == a.kind && e.name == a.name && e.components == a.components)
        x = &e;
    if (extra != 0 && (x == nullptr || x->vertex_count() != extra))
      damaged("no " + std::string(kind_name(a.kind)) + " '" + a.name +
              "' for the vertices no face uses");
    if (a.vertex_count() != nv)
      damaged("attribute '" + a.name + "' does not fit the decoded mesh");
    extra_of.push_back(x);
  }
  if (!r.order.empty() && r.order.size() != nv - r.copies.size() + extra)
    damaged("the vertex order does not fit the mesh");
  return extra_of;
}

/// D's vertex -> output vertex (a copy: its original's); empty when there are no copies
/// and no `source` to fill.
std::vector<uint32_t> output_vertex_of(const IndexPairs &copies, uint32_t nv, bool source) {
  std::vector<uint32_t> out_of;
  if (copies.empty() && !source)
    return out_of;
  out_of.assign(nv, kNone);
  size_t next_copy = 0;
  uint32_t next = 0;
  for (uint32_t v = 0; v < nv; ++v)
    if (next_copy < copies.size() && copies[next_copy].first == v)
      out_of[v] = out_of[copies[next_copy++].second];
    else
      out_of[v] = next++;
  return out_of;
}

/// The output positions, in D's array: the copies dropped (kept rows move down, in place),
/// the extra vertices appended.
void output_positions(std::vector<float> &positions, const LosslessRecord &r, const Quantizer &grid,
                      uint32_t nv) {
  size_t c = 0, kept = 0;
  for (uint32_t v = 0; v < nv && !r.copies.empty(); ++v) {
    if (c < r.copies.size() && r.copies[c].first == v) {
      ++c;
      continue;
    }
    std::copy(&positions[3 * size_t(v)], &positions[3 * size_t(v)] + 3, &positions[3 * kept++]);
  }
  if (!r.copies.empty())
    positions.resize(3 * kept);
  positions.reserve(positions.size() + 3 * (r.extra_q.size() / 3));
  for (size_t i = 0; i < r.extra_q.size(); ++i)
    positions.push_back(grid.dequantize(static_cast<int>(i % 3), uint32_t(r.extra_q[i])));
}

/// Writes the output faces of D's faces, met in canonical order: each face with its flip,
/// its extra copies and its per-corner values (D's corner k is the output face's corner k,
/// but for a flip); a face the record adds back repeating a vertex gets zeros and
/// material 0.
class FaceWriter {
public:
  FaceWriter(const Mesh &decoded, const LosslessRecord &r, const std::vector<uint32_t> &out_of,
             Mesh &out)
      : decoded_(decoded), r_(r), out_of_(out_of), out_(out),
        uv_(!decoded.corner_texcoords.empty()), mat_(!decoded.face_materials.empty()) {
    const uint32_t nf = static_cast<uint32_t>(decoded.triangle_count());
    faces_ = size_t(nf) + r.degenerate.size();
    for (const auto &d : r.duplicates)
      faces_ += d.second;
    if ((uv_ && decoded.corner_texcoords.size() != 6 * size_t(nf)) ||
        (mat_ && decoded.face_materials.size() != nf))
      throw Error(Error::Kind::Internal,
                  "internal error: the per-corner values do not fit the mesh");
    if (uv_)
      out.corner_texcoords.assign(6 * faces_, 0.0f);
    if (mat_)
      out.face_materials.assign(faces_, 0);
  }
  /// The output's face count.
  size_t faces() const { return faces_; }
  /// The i-th face in canonical order, D's face g, as (a, b, c) in D's numbering.
  void put(uint32_t i, uint32_t g, uint32_t a, uint32_t b, uint32_t c) {
    uint32_t f[3] = {map(a), map(b), map(c)};
    int order[3] = {0, 1, 2};
    if (flip_ < r_.flipped.size() && r_.flipped[flip_] == i) {
      std::swap(f[1], f[2]);
      std::swap(order[1], order[2]);
      ++flip_;
    }
    uint32_t n = 1;
    if (dup_ < r_.duplicates.size() && r_.duplicates[dup_].first == i)
      n += r_.duplicates[dup_++].second;
    for (uint32_t k = 0; k < n; ++k, at_ += 3) {
      std::copy(f, f + 3, &out_.triangles[at_]);
      if (uv_)
        for (int j = 0; j < 3; ++j) {
          out_.corner_texcoords[2 * (at_ + j)] =
              decoded_.corner_texcoords[6 * size_t(g) + 2 * order[j]];
          out_.corner_texcoords[2 * (at_ + j) + 1] =
              decoded_.corner_texcoords[6 * size_t(g) + 2 * order[j] + 1];
        }
      if (mat_)
        out_.face_materials[at_ / 3] = decoded_.face_materials[g];
    }
  }
  /// The degenerate faces, after D's.
  void put_degenerate() {
    for (const auto &d : r_.degenerate) {
      const uint32_t f[3] = {d[0], d[0], d[1]};
      std::copy(f, f + 3, &out_.triangles[at_]);
      at_ += 3;
    }
  }

private:
  uint32_t map(uint32_t v) const { return out_of_.empty() ? v : out_of_[v]; }
  const Mesh &decoded_;
  const LosslessRecord &r_;
  const std::vector<uint32_t> &out_of_;
  Mesh &out_;
  const bool uv_, mat_;
  size_t faces_ = 0, flip_ = 0, dup_ = 0, at_ = 0;
};

/// The output faces: for the i-th face of D in canonical order, its flip and its extra
/// copies, then the degenerate faces. Ids a mesh's own: D's faces bucketed, then written
/// in D's triangle array (read no more); else through canonical_face_order.
void output_faces(Mesh &decoded, const LosslessRecord &r, const std::vector<uint32_t> &out_of,
                  Mesh &out) {
  FaceWriter writer(decoded, r, out_of, out);
  const uint32_t nf = static_cast<uint32_t>(decoded.triangle_count());
  const uint32_t top = decoded.triangles.empty()
                           ? 0
                           : *std::max_element(decoded.triangles.begin(), decoded.triangles.end());
  if (dense_ids(decoded.triangles, top)) {
    std::vector<uint32_t> end;
    std::vector<Keyed> by;
    canonical_buckets(decoded.triangles, top, end, by);
    out.triangles = std::move(decoded.triangles); // (read no more: `by` holds the faces)
    out.triangles.resize(3 * writer.faces());
    for (uint32_t k0 = 0, i = 0; i < nf; ++i) {
      while (end[k0] == i)
        ++k0;
      const uint32_t k1 = uint32_t(by[i].key >> 32), k2 = uint32_t(by[i].key);
      const uint32_t s = by[i].id & 3, g = by[i].id >> 2; // D's face g: (k0, k1, k2) rotated back
      if (s == 0)
        writer.put(i, g, k0, k1, k2);
      else if (s == 1)
        writer.put(i, g, k2, k0, k1);
      else
        writer.put(i, g, k1, k2, k0);
    }
  } else {
    const std::vector<uint32_t> order = canonical_face_order(decoded.triangles);
    out.triangles.resize(3 * writer.faces());
    for (uint32_t i = 0; i < nf; ++i) {
      const uint32_t *t = &decoded.triangles[3 * size_t(order[i])];
      writer.put(i, order[i], t[0], t[1], t[2]);
    }
  }
  writer.put_degenerate();
}

/// The textures, materials and vertex attributes (D's `nv` vertices, D's positions moved
/// out already): an output vertex has those of the decoded vertex it comes from (its copies carry
/// the same values: the cut copies attributes); the extra vertices, those the record stores (bit
/// for bit).
void output_attributes(Mesh &decoded, const LosslessRecord &r,
                       const std::vector<const VertexAttribute *> &extra_of, uint32_t nv,
                       Mesh &out) {
  const size_t extra = r.extra_q.size() / 3;
  out.texture_files = std::move(decoded.texture_files);
  out.materials = std::move(decoded.materials);
  out.texture_images = std::move(decoded.texture_images);
  out.corner_texcoord_bits = decoded.corner_texcoord_bits;
  out.corner_texcoord_bound = decoded.corner_texcoord_bound;
  for (size_t i = 0; i < decoded.attributes.size(); ++i) {
    const VertexAttribute *x = extra_of[i];
    VertexAttribute b = std::move(decoded.attributes[i]);
    size_t c = 0; // the copies, in increasing vertex order, are dropped
    if (!r.copies.empty())
      keep_vertex_rows(b, nv, [&](size_t v) {
        if (c < r.copies.size() && r.copies[c].first == v) {
          ++c;
          return false;
        }
        return true;
      });
    if (x != nullptr && extra != 0) {
      b.colour.insert(b.colour.end(), x->colour.begin(), x->colour.end());
      b.values.insert(b.values.end(), x->values.begin(), x->values.end());
    }
    out.attributes.push_back(std::move(b));
  }
}

/// Output vertex o becomes input vertex order[o]: positions, faces and attributes
/// renumbered (the order's size is checked by check_record_fits).
void apply_vertex_order(const std::vector<uint32_t> &order, Mesh &out) {
  std::vector<float> p(out.positions.size());
  for (size_t o = 0; o < order.size(); ++o)
    std::copy(&out.positions[3 * o], &out.positions[3 * o] + 3, &p[3 * size_t(order[o])]);
  out.positions.swap(p);
  for (uint32_t &v : out.triangles)
    v = order[v];
  for (VertexAttribute &a : out.attributes) {
    const size_t n = a.components;
    auto permute = [&](auto &values) {
      auto moved = values;
      for (size_t o = 0; o < order.size(); ++o)
        for (size_t k = 0; k < n; ++k)
          moved[size_t(order[o]) * n + k] = values[o * n + k];
      values.swap(moved);
    };
    if (a.kind == AttributeKind::Colour)
      permute(a.colour);
    else
      permute(a.values);
  }
}

/// For each output vertex, the first vertex of D it comes from (kNone: an extra vertex).
std::vector<uint32_t> source_vertices(const std::vector<uint32_t> &out_of,
                                      const std::vector<uint32_t> &order, size_t out_vertices) {
  std::vector<uint32_t> source(out_vertices, kNone);
  for (uint32_t v = 0; v < out_of.size(); ++v) {
    const uint32_t o = order.empty() ? out_of[v] : order[out_of[v]];
    if (source[o] == kNone)
      source[o] = v;
  }
  return source;
}

} // namespace

Mesh apply_lossless_record(Mesh &&decoded, const LosslessRecord &r, const Quantizer &grid,
                           std::vector<uint32_t> *source) {
  // Worked in place on D's own arrays (a full decode hands its mesh over): the output
  // vertices are D's less the copies, then the extra vertices; the faces D's in canonical
  // order, written where D's were once bucketed. What can be wrong is checked first: a
  // damaged record throws with D untouched (skip_damaged keeps it, the cut mesh).
  const std::vector<const VertexAttribute *> extra_of = check_record_fits(decoded, r);
  const uint32_t nv = static_cast<uint32_t>(decoded.vertex_count());
  const std::vector<uint32_t> out_of = output_vertex_of(r.copies, nv, source != nullptr);
  Mesh out;
  out.positions = std::move(decoded.positions);
  output_positions(out.positions, r, grid, nv);
  output_faces(decoded, r, out_of, out);
  output_attributes(decoded, r, extra_of, nv, out);
  if (!r.order.empty())
    apply_vertex_order(r.order, out);
  if (source)
    *source = source_vertices(out_of, r.order, out.vertex_count());
  return out;
}

} // namespace pomar
