#include "drt/scene/texture_cache.h"

#include <system_error>

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
    if (bytes > budget_ - bytes_) {
        const auto amount = [](std::uint64_t b) {
            return b >= (1u << 20) ? std::to_string(b >> 20) + " MiB"
                                   : std::to_string(b) + " bytes";
        };
        throw ImageError(printable(path.string()) + ": textures would take " +
                         amount(bytes_ + bytes) + " with this image of " +
                         std::to_string(image.width) + "x" + std::to_string(image.height) +
                         ", past the texture memory budget of " + amount(budget_));
    }
    bytes_ += bytes;
    auto mipmap = std::make_shared<const MipMap>(image);
    cache_.emplace(std::pair{key.string(), encoding}, mipmap);
    return mipmap;
}

}  // namespace drt
