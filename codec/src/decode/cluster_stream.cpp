// Cluster blocks read on demand; see cluster_stream.h.
#include "decode/cluster_stream.h"

#include <algorithm>
#include <string>

#include "format/file_format.h"

namespace pomar {

void ClusterStream::init(ByteSource *source, uint32_t id, uint64_t offset, uint32_t size,
                         uint8_t check, ReadStats *stats) {
  source_ = source;
  id_ = id;
  offset_ = offset;
  size_ = size;
  check_ = check;
  stats_ = stats;
}

void ClusterStream::fail_check() const {
  throw Error(Error::Kind::DamagedFile,
              "damaged .pomar file: checksum mismatch in the block of cluster " +
                  std::to_string(id_))
      .in_block(Error::kNoBlock, id_);
}

size_t ClusterStream::more(size_t needed) {
  if (failed_)
    fail_check();
  const size_t size = block_.size();
  if (loaded_ >= size)
    return loaded_; // past the end: the decoder reads zeros (and notices overruns)
  const size_t upto = std::min(size, std::max(needed, loaded_ + kChunk));
  {
    const std::lock_guard<std::mutex> guard(stats_->lock);
    source_->read(offset_ + loaded_, upto - loaded_, block_.data() + loaded_);
    stats_->bytes += upto - loaded_;
    if (loaded_ == 0)
      ++stats_->blocks;
  }
  loaded_ = upto;
  if (loaded_ == size && !checked_) {
    failed_ = !passes_block_check(block_.data(), size, check_);
    if (failed_)
      fail_check();
    checked_ = true;
  }
  return loaded_;
}

void ClusterStream::start(bool whole) {
  // A truncated file (accepted with skip_damaged): nothing is allocated for a block that
  // is not there.
  if (offset_ + size_ > source_->size())
    throw Error(Error::Kind::TruncatedFile, "truncated .pomar file: the block of cluster " +
                                                std::to_string(id_) + " ends at byte " +
                                                std::to_string(offset_ + size_) +
                                                ", the file has " + std::to_string(source_->size()))
        .in_block(Error::kNoBlock, id_);
  if (failed_)
    fail_check();
  if (block_.empty() && size_ > 0)
    block_.resize(size_);
  if (whole)
    more(block_.size());
  else if (loaded_ < std::min<size_t>(block_.size(), kChunk))
    more(std::min<size_t>(block_.size(), kChunk));
  rc_.reset(block_.data(), loaded_, this);
}

} // namespace pomar
