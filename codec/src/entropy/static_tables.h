// Static models of the clustered levels (our answer to the paper's Figure 11: every
// cluster re-learning its models). The encoder records every cluster's symbols, counts
// them per model over all clusters of a level, freezes each level's models on those
// counts, stores the frozen frequencies once in the file's global part, and codes every
// cluster block against them: no per-cluster learning cost, so bits per vertex hardly
// depend on the number of clusters.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "entropy/models.h"
#include "entropy/range_coder.h"

namespace pomar {

/// Stands in for a RangeEncoder: records symbols (with their model) instead of coding.
class SymbolRecorder {
public:
  struct Event {
    void *model; // FrequencyModel* or BitModel*; null for bypass bits
    uint32_t value;
    uint8_t kind;   // 0 frequency symbol, 1 binary, 2 bypass bits
    uint8_t nbits;  // bypass only
    uint8_t stream; // 0 connectivity, 1 geometry, 2 + k attribute code k (statistics only)
  };
  void encode(FrequencyModel &m, int s) { events.push_back({&m, uint32_t(s), 0, 0, stream}); }
  void encode_bit(BitModel &m, int bit) { events.push_back({&m, uint32_t(bit), 1, 0, stream}); }
  void encode_bypass(uint32_t v, int nbits) {
    events.push_back({nullptr, v, 2, uint8_t(nbits), stream});
  }
  void finish() {}
  std::vector<Event> events;
  uint8_t stream = 0;
};

/// A view of a recorder that tags its events with a stream (what EncoderCodec writes to).
struct RecorderStream {
  SymbolRecorder *recorder;
  uint8_t stream;
  void encode(FrequencyModel &m, int s) {
    recorder->stream = stream;
    recorder->encode(m, s);
  }
  void encode_bit(BitModel &m, int bit) {
    recorder->stream = stream;
    recorder->encode_bit(m, bit);
  }
  void encode_bypass(uint32_t v, int nbits) {
    recorder->stream = stream;
    recorder->encode_bypass(v, nbits);
  }
  void finish() {}
};

/// Freezes the models of the clustered levels, level after level, each on the symbols its
/// level recorded (so the encoder can code and forget a level before recording the next).
/// A model whose previous-level frequencies code this level nearly as well as its own
/// would (within what storing its own costs) reuses them: call freeze() in level order.
class LevelFreezer {
public:
  void freeze(Models &level, const std::vector<SymbolRecorder> &recordings);

private:
  std::vector<std::vector<uint16_t>> previous_; // per model slot: frozen frequencies (empty: unused)
};

/// Range-code a recording into `rc` with the (frozen) models its events point to (a
/// cluster's encoder lives across levels: call once per level, finish() after the last).
/// Adds the ideal code lengths per stream to bits[stream]: 0 connectivity, 1 geometry,
/// 2 + k attribute code k (the array must have room for every stream recorded).
void code_recording(const SymbolRecorder &recording, RangeEncoder &rc, double *bits);

/// The log-scale code (1..103) whose stored frequency is nearest to f >= 1 (smallest code
/// on ties); log_code_reference is the plain search over every code, kept for the tests.
uint32_t log_code(uint32_t f);
uint32_t log_code_reference(uint32_t f);

/// Serialize / read back the frozen models of every clustered level.
std::vector<uint8_t> write_tables(std::vector<Models> &models);
/// Throws pomar::Error on damaged tables. `attributes`: the file's attribute code models
/// (Models::attr; their frozen tables follow the geometry's in each level).
std::vector<Models> read_tables(const uint8_t *data, size_t size, size_t levels,
                                const std::vector<AttributeCodeModels> &attributes = {});

} // namespace pomar
