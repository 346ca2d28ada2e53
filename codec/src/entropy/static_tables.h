// Static models of the clustered levels (our answer to the paper's Figure 11: every
// cluster re-learning its models). The encoder records every cluster's symbols, counts
// them per model over all clusters of a level, freezes each level's models on those
// counts, stores the frozen frequencies once in the file's global part, and codes every
// cluster block against them: no per-cluster learning cost, so bits per vertex hardly
// depend on the number of clusters.
#pragma once

#include <cstdint>
#include <vector>

#include "entropy/models.h"
#include "entropy/range_coder.h"

namespace pomar {

/// Numbers every model of one level's Models by its slot, its place in for_each_model's
/// order, and finds a model's slot from its address. The models lie in a few arrays of one
/// model type each (s_v's binary models, each vector of frequency models, the mantissa
/// bits, each attribute code's classes and top bits): a slot is an array's first slot plus
/// the model's index in it. Also lays out one counter per symbol of every model (2 for a
/// binary model), for the freezer's counts and the frozen code lengths.
class ModelSlots {
public:
  explicit ModelSlots(Models &level);
  uint32_t slot(const FrequencyModel *m) const { return find(frequency_arrays_, m); }
  uint32_t slot(const BitModel *m) const { return find(bit_arrays_, m); }
  uint32_t slots() const { return static_cast<uint32_t>(first_symbol_.size()); }
  void *model(uint32_t slot) const { return models_[slot]; }
  bool is_bit(uint32_t slot) const { return is_bit_[slot] != 0; }
  /// The slot's number of symbols (2 for a binary model).
  uint32_t symbols(uint32_t slot) const {
    return (slot + 1 < slots() ? first_symbol_[slot + 1] : symbols_) - first_symbol_[slot];
  }
  /// Where the slot's symbols start among all models' symbols (symbols() of them in all).
  uint32_t first_symbol(uint32_t slot) const { return first_symbol_[slot]; }
  uint32_t symbols() const { return symbols_; }

private:
  struct Array {
    uintptr_t begin;
    uintptr_t bytes;
    uint32_t first_slot;
  };
  /// Hot (once per recorded symbol): a few arrays, one unsigned comparison each.
  template <class Model> static uint32_t find(const std::vector<Array> &arrays, const Model *m) {
    const uintptr_t p = reinterpret_cast<uintptr_t>(m);
    for (const Array &a : arrays)
      if (p - a.begin < a.bytes)
        return a.first_slot + static_cast<uint32_t>((p - a.begin) / sizeof(Model));
    outside_level();
  }
  [[noreturn]] static void outside_level();
  std::vector<Array> frequency_arrays_, bit_arrays_;
  std::vector<void *> models_;         // per slot
  std::vector<uint32_t> first_symbol_; // per slot
  std::vector<uint8_t> is_bit_;        // per slot
  uint32_t symbols_ = 0;
};

/// Stands in for a RangeEncoder: records symbols (with their model's slot) instead of
/// coding. An event is 8 bytes (a 10M-vertex encode records about 10^8 of them in its
/// finest level). Cache-line aligned: neighbouring clusters record on different threads.
class alignas(64) SymbolRecorder {
public:
  struct Event {
    uint32_t model; // ModelSlots slot; bypass bits: their count
    uint32_t word;  // value (24 bits) | kind << 24 (0 frequency symbol, 1 binary, 2 bypass
                    // bits) | stream << 26 (0 connectivity, 1 geometry, 2 + k attribute code k)
    uint32_t value() const { return word & 0xFFFFFFu; }
    uint32_t kind() const { return (word >> 24) & 3u; }
    uint32_t stream() const { return word >> 26; }
    uint32_t nbits() const { return model; }
  };
  void encode(FrequencyModel &m, int s) { events.push_back({slots->slot(&m), pack(s, 0)}); }
  void encode_bit(BitModel &m, int bit) { events.push_back({slots->slot(&m), pack(bit, 1)}); }
  void encode_bypass(uint32_t v, int nbits) { // nbits <= 24
    events.push_back({uint32_t(nbits), pack(v, 2)});
  }
  void finish() {}
  std::vector<Event> events;
  const ModelSlots *slots = nullptr; // of the level being recorded
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

/// Add to `counts` (ModelSlots::symbols() of them) how often `recording` recorded each
/// symbol, at first_symbol(slot) + symbol (bypass bits are not counted).
void count_symbols(const SymbolRecorder &recording, const ModelSlots &slots, uint32_t *counts);

/// Freezes the models of the clustered levels, level after level, each on the symbols its
/// level recorded (so the encoder can code and forget a level before recording the next).
/// A model may reuse the previous level's frequencies: call freeze() in level order.
class LevelFreezer {
public:
  /// `fewest_bits` (version 5 files): each model's frequencies are those that code the
  /// level's symbols with their table in the fewest bits (the level's own, mixed with the
  /// previous level's symbol by symbol, the previous level's, or uniform); false (versions
  /// 1-4): the own or the previous level's, as the encoders that wrote those versions chose.
  explicit LevelFreezer(bool fewest_bits = true) : fewest_bits_(fewest_bits) {}
  /// Freeze the level's models on how often each of their symbols was recorded: `counts`
  /// (at ModelSlots::first_symbol(slot) + symbol: count_symbols over the level's
  /// recordings, in any order).
  void freeze(Models &level, const ModelSlots &slots, std::vector<uint32_t> &&counts);
  /// How often each symbol was recorded in the level last frozen (at first_symbol + symbol).
  const std::vector<uint32_t> &counts() const { return counts_; }

private:
  bool fewest_bits_;
  std::vector<uint32_t> counts_;
  std::vector<std::vector<uint16_t>>
      previous_; // per model slot: frozen frequencies (empty: unused)
};

/// The ideal code length (cost_bits) of every symbol of a frozen level that was recorded
/// (`counts`, LevelFreezer::counts), at ModelSlots::first_symbol(slot) + symbol (0 for the
/// others): computed once per level and symbol, not once per event.
std::vector<double> symbol_costs(const ModelSlots &slots, const std::vector<uint32_t> &counts);

/// Add the ideal code lengths of a recording's events (`costs` of its frozen level) to
/// bits[stream]: 0 connectivity, 1 geometry, 2 + k attribute code k (the array must have
/// room for every stream recorded), in event order.
void add_recording_bits(const SymbolRecorder &recording, const ModelSlots &slots,
                        const std::vector<double> &costs, double *bits);

/// Range-code a recording into `rc` with the (frozen) models its events point to (a
/// cluster's encoder lives across levels: call once per level, finish() after the last).
void code_recording(const SymbolRecorder &recording, const ModelSlots &slots, RangeEncoder &rc);

/// The log-scale code (1..103) whose stored frequency is nearest to f >= 1 (smallest code
/// on ties); log_code_reference is the plain search over every code, kept for the tests.
uint32_t log_code(uint32_t f);
uint32_t log_code_reference(uint32_t f);

/// Serialize / read back the frozen models of every clustered level.
std::vector<uint8_t> write_tables(std::vector<Models> &models);
/// Throws pomar::Error on damaged tables. `patch_rank`: the file's version ranks patches
/// (FileHeader::ranks_patches: which connectivity models the tables hold). `attributes`:
/// the file's attribute code models (Models::attr; their frozen tables follow the
/// geometry's in each level).
std::vector<Models> read_tables(const uint8_t *data, size_t size, size_t levels, bool patch_rank,
                                const std::vector<AttributeCodeModels> &attributes = {});

} // namespace pomar
