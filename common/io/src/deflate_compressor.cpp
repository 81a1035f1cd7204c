// See deflate_compressor.h.
#include "deflate_compressor.h"

#include <libdeflate.h>

namespace toolkit::io::detail {

DeflateCompressor* DeflateCompressor::New() {
  auto* c = new DeflateCompressor;
  c->InitializeObjectBase();
  return c;
}

DeflateCompressor::~DeflateCompressor() {
  if (compressor_) libdeflate_free_compressor(compressor_);
}

libdeflate_compressor* DeflateCompressor::compressor() {
  // VTK's levels 1-9 are zlib's; libdeflate takes 0-12 with the same meaning up to 9.
  if (!compressor_) compressor_ = libdeflate_alloc_compressor(CompressionLevel);
  return compressor_;
}

void DeflateCompressor::SetCompressionLevel(int level) {
  vtkZLibDataCompressor::SetCompressionLevel(level);  // clamps to 1-9
  if (compressor_) libdeflate_free_compressor(compressor_), compressor_ = nullptr;
}

size_t DeflateCompressor::GetMaximumCompressionSpace(size_t size) {
  libdeflate_compressor* c = compressor();
  return c ? libdeflate_zlib_compress_bound(c, size)
           : vtkZLibDataCompressor::GetMaximumCompressionSpace(size);
}

size_t DeflateCompressor::CompressBuffer(unsigned char const* data, size_t size, unsigned char* out,
                                         size_t space) {
  libdeflate_compressor* c = compressor();
  return c ? libdeflate_zlib_compress(c, data, size, out, space) : 0;
}

}  // namespace toolkit::io::detail
