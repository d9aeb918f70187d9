// The one C++ file of skybake: OpenVDB has no C API. Everything here sits
// behind vdb.h's two C functions; no exception leaves this file.
//
// Bytes go through memory: the writer serialises into a buffer and writes
// it with write(2), so that a full disk or a file size limit is reported
// with the system's reason (std::ofstream would lose it), and the random
// UUID OpenVDB puts in the header can be replaced with one derived from the
// content. The reader checks each grid's shape in its metadata before it
// reads the grid.
#include <openvdb/io/Archive.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <unistd.h>

extern "C" {
#include "io.h"
#include "log.h"
#include "vdb.h"
}

namespace
{

constexpr uint64_t kDefaultMaxVoxels = 1ull << 28;
constexpr uint64_t kMaxFileBytes = 1ull << 30;
constexpr int kLeafDim = openvdb::FloatTree::LeafNodeType::DIM; // 8

// The header: magic (8 bytes), file version, library major and minor
// (4 each), the grid offsets flag (1), then the UUID as 36 characters
// (openvdb/io/Archive.cc, writeHeader).
constexpr size_t kUuidOffset = 8 + 4 + 4 + 4 + 1;
constexpr size_t kUuidSize = 36;

// Archive::write(std::ostream&, ..., seekable) is protected; the stream is a
// seekable buffer, so the file gets grid offsets as io::File writes them.
class BufferWriter : public openvdb::io::Archive
{
  public:
    void write_to(std::ostream &os, const openvdb::GridCPtrVec &grids, const openvdb::MetaMap &meta) const
    {
        this->write(os, grids, /*seekable=*/true, meta);
    }
};

// A UUID-shaped string (8-4-4-4-12 hex digits) from the volume's content
// hash and the attributes: the same file gives the same UUID, and two
// different volumes differ in theirs, as tools that cache by UUID expect.
std::string uuid_from(const sb_image *volume, const sb_attribute *attributes, int attribute_count)
{
    char content[SB_HASH_HEX_SIZE];
    sb_image_content_hash(volume, content);
    std::string text = std::string(content) + '\n';
    for (int a = 0; a < attribute_count; a++)
        text += std::string(attributes[a].name) + '=' + attributes[a].value + '\n';
    char hex[SB_HASH_HEX_SIZE];
    sb_hash_bytes(text.data(), text.size(), hex);
    std::string h(hex, 32);
    return h.substr(0, 8) + '-' + h.substr(8, 4) + '-' + h.substr(12, 4) + '-' + h.substr(16, 4) + '-' + h.substr(20);
}

bool looks_like_uuid(const std::string &bytes, size_t at)
{
    if (bytes.size() < at + kUuidSize)
        return false;
    for (size_t i = 0; i < kUuidSize; i++) {
        char c = bytes[at + i];
        bool dash = i == 8 || i == 13 || i == 18 || i == 23;
        if (dash ? c != '-' : !std::isxdigit(static_cast<unsigned char>(c)))
            return false;
    }
    return true;
}

enum sb_result write_bytes(const char *path, const std::string &bytes)
{
    return sb_write_file(path, bytes.data(), bytes.size(), "VDB file");
}

openvdb::math::Transform::Ptr texture_transform(uint32_t width, uint32_t height, uint32_t depth)
{
    openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
    const double n[3] = {double(width), double(height), double(depth)};
    for (int a = 0; a < 3; a++) {
        m[a][a] = 1.0 / n[a];
        m[3][a] = 0.5 / n[a];
    }
    return openvdb::math::Transform::createLinearTransform(m);
}

// One channel as a dense grid: leaves are touched and filled directly.
openvdb::FloatGrid::Ptr channel_grid(const sb_image *v, uint32_t c)
{
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    openvdb::FloatTree &tree = grid->tree();
    const uint64_t row = v->width, slice = uint64_t(v->width) * v->height;
    for (uint32_t z0 = 0; z0 < v->depth; z0 += kLeafDim)
        for (uint32_t y0 = 0; y0 < v->height; y0 += kLeafDim)
            for (uint32_t x0 = 0; x0 < v->width; x0 += kLeafDim) {
                auto *leaf = tree.touchLeaf(openvdb::Coord(int(x0), int(y0), int(z0)));
                for (uint32_t z = z0; z < std::min<uint32_t>(z0 + kLeafDim, v->depth); z++)
                    for (uint32_t y = y0; y < std::min<uint32_t>(y0 + kLeafDim, v->height); y++)
                        for (uint32_t x = x0; x < std::min<uint32_t>(x0 + kLeafDim, v->width); x++)
                            leaf->setValueOn(openvdb::Coord(int(x), int(y), int(z)),
                                             v->data[(z * slice + y * row + x) * v->channel_count + c]);
            }
    return grid;
}

std::string meta_string(const openvdb::MetaMap &meta, const char *name)
{
    openvdb::StringMetadata::ConstPtr s = meta.getMetadata<openvdb::StringMetadata>(name);
    return s ? s->value() : std::string();
}

// Channel c of the volume from its grid: a dense fog-volume FloatGrid
// stored as half whose active voxels fill `box` exactly.
enum sb_result read_channel(openvdb::io::File &file, const char *path, uint32_t c, const openvdb::CoordBBox &box,
                            sb_image *volume, sb_attribute *attributes, int *attribute_count)
{
    const char *name = volume->channel_names[c];
    openvdb::GridBase::Ptr base = file.readGrid(name);
    openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!grid || !grid->saveFloatAsHalf() || grid->getGridClass() != openvdb::GRID_FOG_VOLUME ||
        grid->background() != 0.0f) {
        sb_error("%s: grid \"%s\": expected a fog-volume FloatGrid stored as half, background 0", path, name);
        return SB_ERR_BAD_IMAGE;
    }
    if (grid->evalActiveVoxelBoundingBox() != box || grid->activeVoxelCount() != box.volume() ||
        grid->tree().activeTileCount() != 0) {
        sb_error("%s: grid \"%s\": its active voxels are not the whole box its metadata gives, in leaves", path, name);
        return SB_ERR_BAD_IMAGE;
    }
    const uint64_t row = volume->width, slice = uint64_t(volume->width) * volume->height;
    for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf)
        for (auto v = leaf->cbeginValueOn(); v; ++v) {
            openvdb::Coord p = v.getCoord();
            volume->data[(p.z() * slice + p.y() * row + p.x()) * volume->channel_count + c] = *v;
        }
    // The "skybake." metadata: the first grid's are returned; every other
    // grid must repeat them.
    int n = 0;
    for (auto m = base->beginMeta(); m != base->endMeta(); ++m) {
        if (m->first.compare(0, 8, "skybake.") != 0)
            continue;
        std::string value = meta_string(*base, m->first.c_str());
        if (c == 0 && attributes && n < SB_FILE_MAX_ATTRIBUTES) {
            std::snprintf(attributes[n].name, sizeof(attributes[n].name), "%s", m->first.c_str());
            std::snprintf(attributes[n].value, sizeof(attributes[n].value), "%s", value.c_str());
        } else if (c > 0 && attributes && attribute_count &&
                   (n >= *attribute_count || m->first != attributes[n].name || value != attributes[n].value)) {
            sb_error("%s: grid \"%s\": metadata %s differs from the first grid's", path, name, m->first.c_str());
            return SB_ERR_BAD_IMAGE;
        }
        n++;
    }
    if (c == 0 && attribute_count)
        *attribute_count = std::min(n, SB_FILE_MAX_ATTRIBUTES);
    else if (attributes && attribute_count && n != *attribute_count) {
        sb_error("%s: grid \"%s\": its metadata differs from the first grid's", path, name);
        return SB_ERR_BAD_IMAGE;
    }
    return SB_OK;
}

} // namespace

extern "C" enum sb_result sb_vdb_write(const char *path, const struct sb_image *volume,
                                       const struct sb_attribute *attributes, int attribute_count)
{
    int64_t bad = sb_image_find_not_half(volume);
    if (bad >= 0) {
        sb_error("%s: value %lld (%.9g) is not a binary16 value, which the file stores; round first", path,
                 static_cast<long long>(bad), double(volume->data[bad]));
        return SB_ERR_NUMERIC;
    }
    std::string bytes;
    try {
        openvdb::initialize();
        openvdb::GridCPtrVec grids;
        openvdb::MetaMap file_meta;
        for (int a = 0; a < attribute_count; a++)
            file_meta.insertMeta(attributes[a].name, openvdb::StringMetadata(attributes[a].value));
        for (uint32_t c = 0; c < volume->channel_count; c++) {
            openvdb::FloatGrid::Ptr grid = channel_grid(volume, c);
            grid->setName(volume->channel_names[c]);
            grid->setGridClass(openvdb::GRID_FOG_VOLUME);
            grid->setSaveFloatAsHalf(true);
            grid->setTransform(texture_transform(volume->width, volume->height, volume->depth));
            for (int a = 0; a < attribute_count; a++)
                grid->insertMeta(attributes[a].name, openvdb::StringMetadata(attributes[a].value));
            grids.push_back(grid);
        }
        std::ostringstream os(std::ios_base::out | std::ios_base::binary);
        BufferWriter writer;
        writer.setCompression(openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
        writer.write_to(os, grids, file_meta);
        bytes = os.str();
    } catch (const std::exception &e) {
        sb_error("%s: OpenVDB cannot write the volume: %s", path, e.what());
        return SB_ERR_VDB;
    }
    if (!looks_like_uuid(bytes, kUuidOffset)) {
        sb_error("%s: OpenVDB wrote a header this build does not know (no UUID at byte %zu)", path, kUuidOffset);
        return SB_ERR_VDB;
    }
    bytes.replace(kUuidOffset, kUuidSize, uuid_from(volume, attributes, attribute_count));
    return write_bytes(path, bytes);
}

extern "C" enum sb_result sb_vdb_read(const char *path, const char *channel_order, uint64_t max_voxels,
                                      struct sb_image *volume, struct sb_attribute *attributes, int *attribute_count)
{
    std::memset(volume, 0, sizeof(*volume));
    if (attribute_count)
        *attribute_count = 0;
    if (!max_voxels)
        max_voxels = kDefaultMaxVoxels;
    struct stat st;
    if (stat(path, &st) != 0) {
        sb_error("%s: cannot open the VDB file: %s", path, strerror(errno));
        return SB_ERR_IO;
    }
    if (!S_ISREG(st.st_mode) || static_cast<uint64_t>(st.st_size) > kMaxFileBytes) {
        sb_error("%s: not a regular file of at most %llu bytes", path, static_cast<unsigned long long>(kMaxFileBytes));
        return SB_ERR_IO;
    }
    sb_image names = {};
    sb_image_set_channel_names(&names, channel_order);
    uint32_t expect_count = 0;
    while (expect_count < SB_IMAGE_MAX_CHANNELS && names.channel_names[expect_count][0])
        expect_count++;
    enum sb_result res = SB_OK;
    try {
        openvdb::initialize();
        openvdb::io::File file(path);
        file.open(/*delayLoad=*/false);
        // The grids, by name: exactly the channels, each once.
        uint32_t grid_count = 0;
        for (auto n = file.beginName(); n != file.endName(); ++n)
            grid_count++;
        if (grid_count != expect_count) {
            sb_error("%s: holds %u grids, expected %u (%s)", path, grid_count, expect_count, channel_order);
            return SB_ERR_BAD_IMAGE;
        }
        // Shapes from the grids' metadata, before any tree is read.
        openvdb::Vec3i box_min, box_max;
        for (uint32_t c = 0; c < expect_count; c++) {
            const char *name = names.channel_names[c];
            if (!file.hasGrid(name)) {
                sb_error("%s: no grid \"%s\" (expected %s)", path, name, channel_order);
                return SB_ERR_BAD_IMAGE;
            }
            openvdb::GridBase::Ptr meta = file.readGridMetadata(name);
            auto lo = meta->getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MIN);
            auto hi = meta->getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MAX);
            if (!lo || !hi) {
                sb_error("%s: grid \"%s\": no bounding box in its metadata", path, name);
                return SB_ERR_BAD_IMAGE;
            }
            if (c == 0) {
                box_min = lo->value();
                box_max = hi->value();
            }
            uint64_t voxels = 1;
            for (int a = 0; a < 3; a++)
                voxels *= box_max[a] >= 0 && box_max[a] < (1 << 20) ? uint64_t(box_max[a]) + 1 : max_voxels + 1;
            if (box_min != openvdb::Vec3i(0, 0, 0) || lo->value() != box_min || hi->value() != box_max ||
                voxels > max_voxels) {
                sb_error(
                    "%s: grid \"%s\": voxels from (%d, %d, %d) to (%d, %d, %d); expected a box from the origin, the "
                    "same for every grid, of at most %llu voxels",
                    path, name, lo->value()[0], lo->value()[1], lo->value()[2], hi->value()[0], hi->value()[1],
                    hi->value()[2], static_cast<unsigned long long>(max_voxels));
                return SB_ERR_BAD_IMAGE;
            }
        }
        res = sb_image_init_volume(volume, uint32_t(box_max[0]) + 1, uint32_t(box_max[1]) + 1, uint32_t(box_max[2]) + 1,
                                   expect_count);
        if (res)
            return res;
        sb_image_set_channel_names(volume, channel_order);
        const openvdb::CoordBBox box(openvdb::Coord(0), openvdb::Coord(box_max));
        for (uint32_t c = 0; c < expect_count && !res; c++)
            res = read_channel(file, path, c, box, volume, attributes, attribute_count);
    } catch (const std::exception &e) {
        sb_error("%s: OpenVDB cannot read the file: %s", path, e.what());
        res = SB_ERR_VDB;
    }
    if (res)
        sb_image_finish(volume);
    return res;
}
