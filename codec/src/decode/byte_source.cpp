// Byte sources: where the decoder reads a .pomar file from (random_access.h).
#include <cerrno>
#include <cstring>

#include "pomar/random_access.h"

namespace pomar {

void MemorySource::read(uint64_t offset, size_t n, uint8_t *out) {
  if (offset > size_ || n > size_ - offset)
    throw Error(Error::Kind::TruncatedFile,
                "read past the end of the .pomar data (truncated file?)");
  if (n) // an empty source has no data pointer to copy from (found by fuzzing)
    std::memcpy(out, data_ + offset, n);
}

FileSource::FileSource(const std::string &path) : path_(path) {
  file_ = std::fopen(path.c_str(), "rb");
  if (!file_)
    throw Error(Error::Kind::Io, "cannot open " + path + ": " + std::strerror(errno))
        .with_path(path);
  if (std::fseek(file_, 0, SEEK_END) != 0 || std::ftell(file_) < 0) {
    std::fclose(file_);
    throw Error(Error::Kind::Io, "cannot read " + path + ": not a regular file").with_path(path);
  }
  size_ = static_cast<uint64_t>(std::ftell(file_));
}

FileSource::~FileSource() {
  if (file_)
    std::fclose(file_);
}

void FileSource::read(uint64_t offset, size_t n, uint8_t *out) {
  if (offset > size_ || n > size_ - offset)
    throw Error(Error::Kind::TruncatedFile, "truncated .pomar file: " + path_ +
                                                " ends before byte " + std::to_string(offset + n))
        .with_path(path_);
  if (n == 0)
    return;
  if (std::fseek(file_, static_cast<long>(offset), SEEK_SET) != 0 ||
      std::fread(out, 1, n, file_) != n)
    throw Error(Error::Kind::Io, "cannot read " + path_ + ": " + std::strerror(errno))
        .with_path(path_);
}

} // namespace pomar
