#include "drt/scene/texture_cache.h"

#include <system_error>

#include "drt/util/limits.h"
#include "drt/util/text.h"

namespace drt {

std::shared_ptr<const MipMap> TextureCache::get(const std::filesystem::path& path,
                                                TextureEncoding encoding) {
    // The same file under two spellings ("a/../t.png", "t.png") is one texture.
    std::error_code error;
    std::filesystem::path key = std::filesystem::weakly_canonical(path, error);
    if (error) key = path.lexically_normal();
    const auto found = cache_.find({key.string(), encoding});
    if (found != cache_.end()) return found->second;
    const Image image = read_texture(path, encoding);
    const std::uint64_t bytes = MipMap::bytes_for(image.width, image.height);
    if (bytes > kMaxTextureBytes - bytes_) {
        throw ImageError(printable(path.string()) + ": textures would take " +
                         std::to_string((bytes_ + bytes) >> 20) + " MiB with this image of " +
                         std::to_string(image.width) + "x" + std::to_string(image.height) +
                         ", past the " + std::to_string(kMaxTextureBytes >> 20) +
                         " MiB texture memory budget");
    }
    bytes_ += bytes;
    auto mipmap = std::make_shared<const MipMap>(image);
    cache_.emplace(std::pair{key.string(), encoding}, mipmap);
    return mipmap;
}

}  // namespace drt
