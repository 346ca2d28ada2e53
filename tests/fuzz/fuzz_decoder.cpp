// libFuzzer target: the .pomar decoders on arbitrary bytes.
// pomar::Error is the expected way to reject input; anything else (crash, sanitizer
// report, other exception, hang, OOM) is a finding. The byte mutator rarely builds a
// consistent hostile header: fuzz_structure.cpp does that.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "support/hostile_files.h" // exercise_decoders, repair_checksums

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  pomar::hostile::exercise_decoders(data, size);
  // Again with valid checksums, to get past them into the decoders (regressions/
  // decoder-oob-tables-past-end.fuzz-input crashed here before read_layout checked sums).
  if (size >= pomar::kFixedHeaderBytes) {
    std::vector<uint8_t> fixed(data, data + size);
    if (pomar::hostile::repair_checksums(fixed) && !std::equal(fixed.begin(), fixed.end(), data)) {
      if (!pomar::hostile::layout_out_of_bounds(fixed).empty())
        std::abort(); // the layout reader accepted a block outside the file
      pomar::hostile::exercise_decoders(fixed.data(), fixed.size());
    }
  }
  return 0;
}
