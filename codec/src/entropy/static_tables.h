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

/// Names every model of one level's Models in 32 bits: the array holding it (8 bits: the
/// Models struct itself, each vector of models, each attribute's) and its byte offset in
/// that array (24 bits). Lets a recorded event take 8 bytes instead of 16.
class ModelAddresses {
public:
  explicit ModelAddresses(Models &level);
  uint32_t name(const void *model) const;
  void *model(uint32_t name) const {
    return reinterpret_cast<void *>(ranges_[name >> 24].first + (name & 0xFFFFFFu));
  }

private:
  std::vector<std::pair<uintptr_t, uintptr_t>> ranges_; // [begin, end) of each array, sorted
};

/// Stands in for a RangeEncoder: records symbols (with their model) instead of coding.
/// An event is 8 bytes (a 10M-vertex encode records about 10^8 of them in its finest level).
class SymbolRecorder {
public:
  struct Event {
    uint32_t model; // ModelAddresses name; bypass bits: their count
    uint32_t word;  // value (24 bits) | kind << 24 (0 frequency symbol, 1 binary, 2 bypass
                    // bits) | stream << 26 (0 connectivity, 1 geometry, 2 + k attribute code k)
    uint32_t value() const { return word & 0xFFFFFFu; }
    uint32_t kind() const { return (word >> 24) & 3u; }
    uint32_t stream() const { return word >> 26; }
    uint32_t nbits() const { return model; }
  };
  void encode(FrequencyModel &m, int s) { events.push_back({addresses->name(&m), pack(s, 0)}); }
  void encode_bit(BitModel &m, int bit) { events.push_back({addresses->name(&m), pack(bit, 1)}); }
  void encode_bypass(uint32_t v, int nbits) { // nbits <= 24
    events.push_back({uint32_t(nbits), pack(v, 2)});
  }
  void finish() {}
  void *model(const Event &e) const { return addresses->model(e.model); }
  std::vector<Event> events;
  const ModelAddresses *addresses = nullptr; // of the level being recorded
  uint8_t stream = 0;

private:
  uint32_t pack(uint32_t value, uint32_t kind) const {
    return (value & 0xFFFFFFu) | kind << 24 | uint32_t(stream) << 26;
  }
};

/// A view of a recorder that tags its events with a stream (what EncoderCodec writes to).
struct RecorderStream {
  static constexpr bool kRecorder = true; // no ideal code lengths wanted (WantsBits)
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
  std::vector<std::vector<uint16_t>>
      previous_; // per model slot: frozen frequencies (empty: unused)
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
