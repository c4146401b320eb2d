// The image textures a scene loads: each file read and its mip-map built once, however many
// objects use it, and all of them together held within a budget (kMaxTextureBytes).
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "drt/io/texture_file.h"
#include "drt/shading/mipmap.h"
#include "drt/util/limits.h"

namespace drt {

class TextureCache {
  public:
    // `budget`: the bytes all mip-maps together may take (smaller in tests).
    explicit TextureCache(std::uint64_t budget = kMaxTextureBytes) : budget_(budget) {}

    // The mip-map of the image at `path` decoded as `encoding`. Throws ImageError for a file
    // that cannot be read or decoded, or one that does not fit in what is left of the budget.
    std::shared_ptr<const MipMap> get(const std::filesystem::path& path, TextureEncoding encoding);
    std::uint64_t bytes() const { return bytes_; }
    // Files read, each once.
    std::size_t files_read() const { return cache_.size(); }

  private:
    std::map<std::pair<std::string, TextureEncoding>, std::shared_ptr<const MipMap>> cache_;
    std::uint64_t budget_;
    std::uint64_t bytes_ = 0;
};

}  // namespace drt
