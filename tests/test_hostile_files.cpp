// Hostile .pomar files: crafted headers with valid checksums whose sizes, offsets and counts
// lie inside and beyond their valid ranges. The promises of docs/robustness.md ("Untrusted
// input") that these back: the strict layout reader never accepts a block outside the file
// and no size sum wraps; every decoder entry point refuses such a file with pomar::Error or
// decodes it, and never reads outside its buffers (the ASan pass of scripts/test.sh runs this
// same sweep with xxhash and tinyobjloader compiled in, so every byte access is checked).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <pomar/limits.h>

#include "support/hostile_files.h"
#include "support/mesh_gen.h"

namespace pomar {
namespace {

namespace fs = std::filesystem;
using namespace hostile;
const fs::path kRegressions = fs::path(POMAR_SOURCE_DIR) / "tests" / "fuzz" / "regressions";

std::vector<uint8_t> read_bytes(const fs::path &p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<uint8_t> small_file(bool progressive) {
  EncodeOptions o;
  o.progressive = progressive;
  o.clusters = progressive ? 0 : 6;
  o.memory_limit = kNoMemoryLimit;
  return encode(gen::icosphere(2), o);
}

// A version 4 image: the file with two sections (one optional, one required but known to
// nobody, so decoders refuse it after the layout: the sweep covers both kinds of section).
std::vector<uint8_t> sectioned(const std::vector<uint8_t> &file, bool refused) {
  std::vector<Section> s = {{section_tag("TST1"), 0, {1, 2, 3, 4, 5, 6, 7}}};
  if (refused)
    s.push_back({section_tag("TST2"), kSectionRequired, std::vector<uint8_t>(40, 9)});
  return with_sections(file.data(), file.size(), s);
}

std::string error_of(const std::function<void()> &f) {
  try {
    f();
  } catch (const Error &e) {
    return e.what();
  }
  return "";
}

// A progressive image of a larger mesh whose header claims `base_vertices` and `base_faces`
// (every level grown by one vertex and one face over them, so the level table stays
// consistent), its base block zeroed (zero bytes decode as endless zero steps) and every
// checksum recomputed (the header's at least: the base block's too if the layout accepts the
// header, which `*parsed` says).
std::vector<uint8_t> claiming_base(uint64_t base_vertices, uint64_t base_faces, bool *parsed) {
  EncodeOptions o;
  o.progressive = true;
  o.memory_limit = kNoMemoryLimit;
  std::vector<uint8_t> b = encode(gen::icosphere(5), o);
  const uint32_t levels = uint32_t(get_le(b, 48, 4));
  put_le(b, 40, base_vertices, 4);
  put_le(b, 44, base_faces, 4);
  for (uint32_t i = 0; i < levels; ++i) {
    const size_t e = kFixedHeaderBytes + kLevelEntryBytes * i;
    put_le(b, e, base_vertices + i + 1, 4);
    put_le(b, e + 4, base_faces + i + 1, 4);
  }
  put_le(b, 32, base_vertices + levels, 4);
  put_le(b, 36, base_faces + levels, 4);
  const size_t base_at = header_size(b.data(), b.size()); // (the base block follows the header)
  std::fill(b.begin() + long(base_at), b.begin() + long(base_at + get_le(b, 52, 4)), 0);
  *parsed = repair_checksums(b);
  return b;
}

/// Runs `f` in a child whose address space may grow by at most `extra` bytes; returns
/// true if it finished (every call refused the file with pomar::Error or decoded it).
bool within_address_space(uint64_t extra, const std::function<void()> &f) {
  long pages = 0, page = sysconf(_SC_PAGESIZE);
  {
    std::ifstream statm("/proc/self/statm");
    statm >> pages;
  }
  const pid_t child = fork();
  if (child == 0) {
    const rlim_t limit = rlim_t(pages) * rlim_t(page) + extra;
    const rlimit r{limit, limit};
    setrlimit(RLIMIT_AS, &r);
    try {
      f();
    } catch (const Error &) {
    } catch (...) {
      _exit(2);
    }
    _exit(0);
  }
  int status = 0;
  waitpid(child, &status, 0);
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

// Inspection needs memory and time in proportion to the file: the base counts are bounded
// by the base block before anything is sized from them (two sign bits a face, three
// vertices a face at most), and the base mesh is checked without being stored.
TEST(HostileFiles, BaseCountsAreBoundedByTheBaseBlock) {
  bool parsed = true;
  const std::vector<uint8_t> sizes = claiming_base(1000, 1000, &parsed); // (for its sizes)
  const uint64_t base_bytes = get_le(sizes, 52, 4), file = sizes.size();
  // Far more than the block can hold, within the 512 x file size rule: refused by the
  // layout, before a count is used (no loop runs: the message says so).
  const uint64_t huge = 400 * file;
  const std::vector<uint8_t> claims = claiming_base(3 * huge / 2, huge, &parsed);
  EXPECT_FALSE(parsed);
  for (const std::function<void()> &f :
       std::vector<std::function<void()>>{[&] { inspect(claims.data(), claims.size()); },
                                          [&] { check_blocks(claims.data(), claims.size()); },
                                          [&] { decode(claims.data(), claims.size()); }})
    EXPECT_NE(error_of(f).find("cannot be coded in a base mesh block"), std::string::npos)
        << error_of(f);
  // As much as the bounds let through, zero bytes: the positions decode (all zero), the
  // first face repeats a vertex and stops the stream; nothing of the claimed mesh is stored.
  const uint64_t faces = 4 * base_bytes + 64;
  const std::vector<uint8_t> zeros = claiming_base(3 * faces, faces, &parsed);
  EXPECT_TRUE(parsed);
  for (const std::function<void()> &f :
       std::vector<std::function<void()>>{[&] { inspect(zeros.data(), zeros.size()); },
                                          [&] { check_blocks(zeros.data(), zeros.size()); }})
    EXPECT_NE(error_of(f).find("base mesh face repeats a vertex"), std::string::npos)
        << error_of(f);
    // Memory: every entry point within 64 MiB more address space (a child with RLIMIT_AS).
#if !defined(__SANITIZE_ADDRESS__)
  for (const std::vector<uint8_t> *b : {&claims, &zeros})
    EXPECT_TRUE(within_address_space(uint64_t(64) << 20, [&] {
      for (const std::function<void()> &f : std::vector<std::function<void()>>{
               [&] { inspect(b->data(), b->size()); }, [&] { check_blocks(b->data(), b->size()); },
               [&] { decode(b->data(), b->size()); }})
        error_of(f);
    }));
#endif
}

// The file of ../shared/regressions (found by a 20-minute fuzz_decoder run): tables placed
// past the end of a 636-byte file and a cluster data size of 2^64 - 1349 whose sum wrapped
// back inside the file. Every entry point must refuse it before reading a byte of it.
TEST(HostileFiles, TablesPastTheEndWithAWrappingClusterSizeAreRefused) {
  const std::vector<uint8_t> f = read_bytes(kRegressions / "decoder-oob-tables-past-end.pomar");
  ASSERT_EQ(f.size(), 636u);
  const std::string why = error_of([&] { inspect(f.data(), f.size()); });
  EXPECT_NE(why.find("cluster data size"), std::string::npos) << why;
  EXPECT_NE(why.find("impossible"), std::string::npos) << why;
  EXPECT_FALSE(error_of([&] { (void)decode(f.data(), f.size()); }).empty());
  EXPECT_FALSE(error_of([&] { (void)check_blocks(f.data(), f.size()); }).empty());
  EXPECT_FALSE(error_of([&] {
                 SelectiveDecoder d(std::make_unique<MemorySource>(f.data(), f.size()));
               }).empty());
  EXPECT_EQ(hostile::exercise_decoders(f.data(), f.size()), 0);
  // The raw fuzzer input, as the harness runs it (as is, then with checksums repaired).
  std::vector<uint8_t> raw = read_bytes(kRegressions / "decoder-oob-tables-past-end.fuzz-input");
  ASSERT_FALSE(raw.empty());
  hostile::exercise_decoders(raw.data(), raw.size());
  if (hostile::repair_checksums(raw)) {
    EXPECT_EQ(hostile::exercise_decoders(raw.data(), raw.size()), 0);
  }
}

// A size that would make the offset sum wrap is refused by name, whichever block it is.
TEST(HostileFiles, SizesThatWouldWrapAnOffsetAreRefusedByName) {
  const std::vector<uint8_t> file = small_file(false);
  for (const hostile::Field &field : hostile::header_fields(file)) {
    if (field.bytes != 8)
      continue;
    std::vector<uint8_t> b = file;
    hostile::put_le(b, field.at, ~uint64_t(0) - 100, 8);
    hostile::repair_checksums(b); // the header checksum at least (the layout then fails)
    const std::string why = error_of([&] { read_layout(b.data(), b.size(), b.size(), true); });
    EXPECT_NE(why.find("impossible"), std::string::npos) << field.name << ": " << why;
  }
}

// The sweep: every header field of a progressive and a clustered file set to each of its
// interesting values, checksums repaired. The layout reader never accepts a block outside
// the file, every decoder refuses with pomar::Error or decodes, and the intact file still
// decodes everywhere (so the sweep exercises real decoders, not only the header check).
TEST(HostileFiles, EveryHeaderFieldAtItsEdgesIsRefusedOrDecodedInBounds) {
  for (int kind = 0; kind < 4; ++kind) {
    const bool progressive = kind % 2 == 0;
    const std::vector<uint8_t> file =
        kind < 2 ? small_file(progressive) : sectioned(small_file(progressive), kind == 3);
    ASSERT_EQ(hostile::exercise_decoders(file.data(), file.size()), kind == 3 ? 1 : 6);
    size_t cases = 0, accepted_by_layout = 0, refused_everywhere = 0;
    for (const hostile::Field &field : hostile::header_fields(file)) {
      for (uint64_t value : hostile::interesting_values(field, file)) {
        std::vector<uint8_t> b = file;
        hostile::put_le(b, field.at, value, field.bytes);
        hostile::repair_checksums(b);
        ++cases;
        const std::string outside = hostile::layout_out_of_bounds(b);
        EXPECT_TRUE(outside.empty()) << field.name << " = " << value << ": the layout accepts the "
                                     << outside << " outside the file";
        try {
          read_layout(b.data(), b.size(), b.size(), false);
          ++accepted_by_layout;
        } catch (const Error &) {
        }
        if (hostile::exercise_decoders(b.data(), b.size()) == 0)
          ++refused_everywhere;
      }
    }
    // Most edits make an inconsistent header, some (e.g. a size one byte smaller) a valid
    // header with a damaged block: both kinds must be present for the sweep to mean much.
    EXPECT_GT(cases, 300u);
    EXPECT_GT(refused_everywhere, cases / 2);
    EXPECT_GT(accepted_by_layout, 10u);
  }
}

// Truncation at every byte of the global part of a clustered file, with and without the
// tolerant mode: an error or a mesh, never a read past the end.
TEST(HostileFiles, EveryTruncationOfTheGlobalPartIsRefusedOrDecoded) {
  const std::vector<uint8_t> file = small_file(false);
  const FileLayout L = read_layout(file.data(), file.size());
  for (size_t n = 0; n <= L.global_bytes + 8 && n <= file.size(); ++n) {
    // An exact-size heap copy: ASan sees a read one byte past it.
    std::unique_ptr<uint8_t[]> cut(new uint8_t[n ? n : 1]);
    std::copy(file.begin(), file.begin() + n, cut.get());
    hostile::exercise_decoders(cut.get(), n);
  }
}

} // namespace
} // namespace pomar
