// Cluster blocks read on demand; see cluster_stream.h.
#include "decode/cluster_stream.h"

#include <algorithm>
#include <string>

#include "format/file_format.h"

namespace pomar {

void ClusterStream::init(ByteSource *source, uint32_t id, uint64_t offset, uint32_t size,
                         uint32_t check, uint32_t mask, ReadStats *stats) {
  source_ = source;
  id_ = id;
  offset_ = offset;
  size_ = size;
  check_ = check;
  mask_ = mask;
  stats_ = stats;
}

std::string ClusterStream::check_message() const {
  return "damaged .pomar file: checksum mismatch in the block of cluster " + std::to_string(id_);
}

bool ClusterStream::missing() const { return offset_ + size_ > source_->size(); }

std::string ClusterStream::missing_message() const {
  return "truncated .pomar file: the block of cluster " + std::to_string(id_) + " ends at byte " +
         std::to_string(offset_ + size_) + ", the file has " + std::to_string(source_->size());
}

void ClusterStream::fail_check() const {
  throw Error(Error::Kind::DamagedFile, check_message()).in_block(Error::kNoBlock, id_);
}

bool ClusterStream::load(size_t upto) {
  {
    const std::lock_guard<std::mutex> guard(stats_->lock);
    source_->read(offset_ + loaded_, upto - loaded_, block_.data() + loaded_);
    stats_->bytes += upto - loaded_;
    if (loaded_ == 0)
      ++stats_->blocks;
  }
  loaded_ = upto;
  if (loaded_ == block_.size() && !checked_) {
    failed_ = !passes_block_check(block_.data(), loaded_, check_, mask_);
    checked_ = !failed_;
  }
  return !failed_;
}

size_t ClusterStream::more(size_t needed) {
  if (failed_)
    fail_check();
  const size_t size = block_.size();
  if (loaded_ >= size)
    return loaded_; // past the end: the decoder reads zeros (and notices overruns)
  if (!load(std::min(size, std::max(needed, loaded_ + kChunk))))
    fail_check();
  return loaded_;
}

void ClusterStream::start(bool whole) {
  // A truncated file (accepted with skip_damaged): nothing is allocated for a block that
  // is not there.
  if (missing())
    throw Error(Error::Kind::TruncatedFile, missing_message()).in_block(Error::kNoBlock, id_);
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

std::string ClusterStream::problem() {
  if (missing())
    return missing_message();
  if (failed_)
    return check_message();
  if (checked_ || size_ == 0)
    return {};
  if (block_.empty())
    block_.resize(size_);
  return load(block_.size()) ? std::string() : check_message();
}

} // namespace pomar
