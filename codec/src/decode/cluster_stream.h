// A cluster's block (paper section 5.2: each cluster's clustered levels are one range-coded
// stream), read from the byte source in small chunks as its decoder consumes it, so that
// a coarse request reads only the first bytes of a block.
#pragma once

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "entropy/range_coder.h"
#include "pomar/random_access.h"

namespace pomar {

/// Bytes and blocks read so far, shared by all streams of a decoder, and the lock of the
/// source they read from (streams are decoded on several threads; a ByteSource needs not
/// be thread-safe: it is called by one thread at a time).
struct ReadStats {
  uint64_t bytes = 0;
  uint32_t blocks = 0;
  std::mutex lock;
};

class ClusterStream : public StreamRefill {
public:
  static constexpr size_t kChunk = 4; // bytes per on-demand read of a cluster block

  /// Cluster `id`'s block: `size` bytes at `offset` of `source`, with its check (the bits
  /// `mask` of its XXH32: ClusterIndex).
  void init(ByteSource *source, uint32_t id, uint64_t offset, uint32_t size, uint32_t check,
            uint32_t mask, ReadStats *stats);
  /// A longer check for the block (a BCHK section read after init), before it is read.
  void set_check(uint32_t check, uint32_t mask) {
    check_ = check;
    mask_ = mask;
  }
  /// (Re)start the stream from its first byte; `whole` reads the block at once (it will be
  /// decoded to the end, or its check must pass first), otherwise bytes are read as the
  /// decoder needs them. Throws if the file ends before the block (truncated file).
  void start(bool whole);
  /// The checks start(true) makes, without the throw: the block is read whole if the file
  /// holds it. Returns why start(true) would fail (empty: it would not).
  std::string problem();
  RangeDecoder &decoder() { return rc_; }
  /// The block passed its check (it has been read whole).
  bool checked() const { return checked_; }
  /// The block, if it has been read whole (else null).
  const std::vector<uint8_t> *whole_block() const { return loaded_ == size_ ? &block_ : nullptr; }
  size_t more(size_t needed) override;

private:
  [[noreturn]] void fail_check() const;
  bool load(size_t upto); // reads up to byte `upto`; false if the whole block fails its check
  bool missing() const;   // the file ends before the block (truncated file)
  std::string missing_message() const;
  std::string check_message() const;
  ByteSource *source_ = nullptr;
  ReadStats *stats_ = nullptr;
  uint32_t id_ = 0, size_ = 0;
  uint64_t offset_ = 0;
  uint32_t check_ = 0, mask_ = 0xFF;
  std::vector<uint8_t> block_; // sized to the whole block; [0, loaded_) read so far
  size_t loaded_ = 0;
  bool checked_ = false;
  bool failed_ = false; // read whole, the check failed: every later start fails the same way
  RangeDecoder rc_;
};

} // namespace pomar
