// The one C++ file of skybake: OpenVDB has no C API. Everything here sits
// behind vdb.h's two C functions; no exception leaves this file.
//
// Bytes go through memory: the writer serialises into a buffer and writes
// it with write(2), so that a full disk or a file size limit is reported
// with the system's reason (std::ofstream would lose it), and the random
// UUID OpenVDB puts in the header can be replaced with one derived from the
// content. The reader checks the file's structure in the caller, then
// OpenVDB parses it in a helper program (read_vdb.c, sandbox.h), which
// checks each grid's shape in its metadata before it reads the grid.
#include <openvdb/io/Archive.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <tbb/task_arena.h>

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
#include "read_vdb.h"
#include "sandbox.h"
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

// ---- the file's structure, checked before OpenVDB parses it ---------------------------
//
// OpenVDB trusts the lengths in a file: a VDB cut to 100 bytes made it
// allocate 20 GB, and other cuts read lengths it never set. So the layout
// OpenVDB's File::open walks (openvdb/io/Archive.cc, File.cc,
// GridDescriptor.cc) is walked here first, every length and offset bounded
// by the file: the header, the file's metadata, then each grid's
// descriptor, whose offsets must lie in order within the file and end
// exactly at its end. What lies inside a grid is left to OpenVDB, in a
// sandboxed process (below).

constexpr int64_t kMagic = 0x56444220;      // OPENVDB_MAGIC, " BDV"
constexpr uint32_t kFirstFileVersion = 222; // node mask compression, the UUID, instancing
constexpr uint32_t kMaxString = 4096, kMaxMeta = 256, kMaxMetaBytes = 1u << 20;

class Cursor
{
  public:
    Cursor(int fd, uint64_t size) : fd_(fd), size_(size)
    {
    }
    uint64_t at() const
    {
        return at_;
    }
    bool ok() const
    {
        return ok_;
    }
    bool seek(uint64_t to)
    {
        return ok_ = ok_ && to <= size_ ? (at_ = to, true) : false;
    }
    bool bytes(void *out, uint64_t n)
    {
        if (!ok_ || n > size_ - at_)
            return ok_ = false;
        char *p = static_cast<char *>(out);
        for (uint64_t done = 0; done < n;) {
            ssize_t got = pread(fd_, p + done, n - done, off_t(at_ + done));
            if (got < 0 && errno == EINTR)
                continue;
            if (got <= 0)
                return ok_ = false;
            done += uint64_t(got);
        }
        at_ += n;
        return true;
    }
    template <typename T> T value()
    {
        T v{};
        bytes(&v, sizeof(v));
        return v;
    }
    // readString: a 32-bit length, then the characters
    bool string(std::string *out, uint32_t max)
    {
        uint32_t n = value<uint32_t>();
        if (!ok_ || n > max)
            return ok_ = false;
        out->resize(n);
        return bytes(&(*out)[0], n);
    }

  private:
    int fd_;
    uint64_t size_, at_ = 0;
    bool ok_ = true;
};

// Empty when the layout holds; else what is wrong, for "path: ...", with
// *code SB_ERR_BAD_IMAGE for a sound VDB file of other grids, else SB_ERR_VDB.
std::string check_structure(int fd, uint64_t size, uint32_t grids_expected, sb_result *code)
{
    *code = SB_ERR_VDB;
    Cursor c(fd, size);
    if (c.value<int64_t>() != kMagic || !c.ok())
        return "not a VDB file (no magic number)";
    uint32_t version = c.value<uint32_t>();
    if (version < kFirstFileVersion || version > openvdb::OPENVDB_FILE_VERSION)
        return "file format version " + std::to_string(version) + ", not one this reader knows (" +
               std::to_string(kFirstFileVersion) + " to " + std::to_string(openvdb::OPENVDB_FILE_VERSION) + ")";
    c.value<uint32_t>(); // the library's major and minor version
    c.value<uint32_t>();
    if (c.value<uint8_t>() != 1)
        return "no grid offsets (skybake's files have them)";
    std::string uuid(kUuidSize, ' ');
    c.bytes(&uuid[0], kUuidSize);
    if (!c.ok() || !looks_like_uuid(uuid, 0))
        return "the header ends early or has no UUID";
    std::string name, type;
    uint32_t metas = c.value<uint32_t>();
    if (!c.ok() || metas > kMaxMeta)
        return "the file's metadata count is cut or past " + std::to_string(kMaxMeta);
    for (uint32_t m = 0; m < metas; m++) {
        if (!c.string(&name, kMaxString) || !c.string(&type, kMaxString))
            return "metadata " + std::to_string(m) + ": its name or type is cut or too long";
        uint32_t n = c.value<uint32_t>();
        if (!c.ok() || n > kMaxMetaBytes || !c.seek(c.at() + n))
            return "metadata \"" + name + "\": its value is cut or larger than 1 MiB";
    }
    int32_t grids = c.value<int32_t>();
    if (c.ok() && grids >= 0 && uint32_t(grids) != grids_expected)
        *code = SB_ERR_BAD_IMAGE;
    if (!c.ok() || grids < 0 || uint32_t(grids) != grids_expected)
        return "holds " + std::to_string(grids) + " grids, expected " + std::to_string(grids_expected) +
               " (the channels)";
    for (int32_t g = 0; g < grids; g++) {
        std::string unique, parent;
        if (!c.string(&unique, kMaxString) || !c.string(&type, kMaxString) || !c.string(&parent, kMaxString))
            return "grid " + std::to_string(g) + ": its descriptor is cut";
        int64_t grid_pos = c.value<int64_t>(), block_pos = c.value<int64_t>(), end_pos = c.value<int64_t>();
        if (!c.ok() || grid_pos < int64_t(c.at()) || block_pos < grid_pos || end_pos < block_pos ||
            uint64_t(end_pos) > size || (g + 1 == grids && uint64_t(end_pos) != size))
            return "grid \"" + unique + "\": its offsets " + std::to_string(grid_pos) + ", " +
                   std::to_string(block_pos) + ", " + std::to_string(end_pos) +
                   " do not lie in order within the file's " + std::to_string(size) + " bytes";
        c.seek(uint64_t(end_pos));
    }
    return std::string();
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

namespace
{

// ---- in the helper program (read_vdb.c): OpenVDB parses ------------------------------------

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

// The grids of the file OpenVDB opens at `file` (the parent's descriptor,
// as /proc/self/fd/N), errors naming `path`.
enum sb_result read_grids(const char *path, const char *file_name, const char *channel_order, uint64_t max_voxels,
                          sb_image *volume, sb_attribute *attributes, int *attribute_count)
{
    sb_image names = {};
    sb_image_set_channel_names(&names, channel_order);
    uint32_t expect_count = 0;
    while (expect_count < SB_IMAGE_MAX_CHANNELS && names.channel_names[expect_count][0])
        expect_count++;
    enum sb_result res = SB_OK;
    try {
        openvdb::initialize();
        openvdb::io::File file(file_name);
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

} // namespace

// The helper's side of sb_vdb_read (read_vdb.h).
extern "C" int sb_vdb_read_task(int out, const void *request, size_t size)
{
    sb_read_vdb_request job = {};
    if (size != sizeof(job))
        return 2;
    std::memcpy(&job, request, sizeof(job));
    job.path[sizeof(job.path) - 1] = '\0';
    job.channel_order[sizeof(job.channel_order) - 1] = '\0';
    sb_read_vdb_answer a = {};
    a.magic = SB_READ_VDB_MAGIC;
    sb_sandbox_capture_log(a.message, sizeof(a.message));
    char file_name[64];
    std::snprintf(file_name, sizeof(file_name), "/proc/self/fd/%d", SB_SANDBOX_FILE_FD);
    sb_image volume = {};
    sb_attribute attributes[SB_FILE_MAX_ATTRIBUTES] = {};
    int attribute_count = 0;
    // One thread: the CPU-time limit then bounds the wall time too.
    tbb::task_arena arena(1);
    arena.execute([&] {
        a.result = read_grids(job.path, file_name, job.channel_order, job.max_voxels, &volume, attributes,
                              &attribute_count);
    });
    if (!a.result) {
        a.width = volume.width;
        a.height = volume.height;
        a.depth = volume.depth;
        a.channel_count = volume.channel_count;
        a.attribute_count = attribute_count;
    }
    bool ok = sb_write_all(out, &a, sizeof(a));
    if (!a.result && ok)
        ok = sb_write_all(out, attributes, sizeof(attributes)) &&
             sb_write_all(out, volume.data, sb_image_float_count(&volume) * sizeof(float));
    sb_image_finish(&volume);
    return ok ? 0 : 1;
}


// ---- in the caller ---------------------------------------------------------------------------

extern "C" enum sb_result sb_vdb_read(const char *path, const char *channel_order, uint64_t max_voxels,
                                      struct sb_image *volume, struct sb_attribute *attributes, int *attribute_count)
{
    std::memset(volume, 0, sizeof(*volume));
    if (attribute_count)
        *attribute_count = 0;
    if (!max_voxels)
        max_voxels = kDefaultMaxVoxels;
    sb_image names = {};
    sb_image_set_channel_names(&names, channel_order);
    uint32_t channels = 0;
    while (channels < SB_IMAGE_MAX_CHANNELS && names.channel_names[channels][0])
        channels++;
    int fd = sb_open_regular(AT_FDCWD, path, true, nullptr);
    if (fd < 0) {
        sb_error("%s: cannot open the VDB file: %s", path, errno == EINVAL ? "not a regular file" : strerror(errno));
        return SB_ERR_IO;
    }
    struct stat st;
    if (fstat(fd, &st) != 0 || static_cast<uint64_t>(st.st_size) > kMaxFileBytes) {
        sb_error("%s: not a file of at most %llu bytes", path, static_cast<unsigned long long>(kMaxFileBytes));
        close(fd);
        return SB_ERR_IO;
    }
    sb_result code;
    std::string wrong = check_structure(fd, uint64_t(st.st_size), channels, &code);
    if (!wrong.empty()) {
        sb_error("%s: %s", path, wrong.c_str());
        close(fd);
        return code;
    }
    // OpenVDB in its helper: the grids' contents are still OpenVDB's to parse.
    // Memory for its tree and our copy: three times the volume, and room
    // for OpenVDB's own buffers.
    sb_read_vdb_request job = {};
    job.max_voxels = max_voxels;
    if (std::snprintf(job.path, sizeof(job.path), "%s", path) >= int(sizeof(job.path)) ||
        std::snprintf(job.channel_order, sizeof(job.channel_order), "%s", channel_order) >=
            int(sizeof(job.channel_order))) {
        sb_error("%s: the path or the channel list is too long to read it", path);
        close(fd);
        return SB_ERR_IO;
    }
    sb_sandbox_limits limits = {};
    limits.cpu_seconds = 60;
    limits.address_space_bytes =
        (128ull << 20) + 3 * std::min(max_voxels, kDefaultMaxVoxels) * channels * sizeof(float);
    sb_sandbox box;
    enum sb_result res = sb_sandbox_start(&box, &limits, SB_READ_VDB_HELPER, &job, sizeof(job), fd);
    close(fd); // the helper has its copy
    if (res)
        return res;
    sb_read_vdb_answer a;
    char why[160];
    if (!sb_sandbox_read(&box, &a, sizeof(a)) || a.magic != SB_READ_VDB_MAGIC) {
        sb_sandbox_finish(&box, why, sizeof(why));
        sb_error("%s: OpenVDB did not finish reading it: its process %s", path, why);
        return SB_ERR_VDB;
    }
    a.message[sizeof(a.message) - 1] = '\0';
    if (a.result) {
        sb_sandbox_finish(&box, nullptr, 0);
        sb_error("%s", a.message[0] ? a.message : "OpenVDB cannot read the file");
        return unsigned(a.result) < SB_RESULT_COUNT ? sb_result(a.result) : SB_ERR_VDB;
    }
    sb_attribute got[SB_FILE_MAX_ATTRIBUTES];
    uint64_t voxels = uint64_t(a.width) * a.height * a.depth;
    if (a.channel_count != channels || !a.width || !a.height || !a.depth || voxels > max_voxels ||
        a.attribute_count < 0 || a.attribute_count > SB_FILE_MAX_ATTRIBUTES) {
        sb_sandbox_finish(&box, nullptr, 0);
        sb_error("%s: the reading process answered %ux%ux%u voxels of %u channels: not what was asked", path, a.width,
                 a.height, a.depth, a.channel_count);
        return SB_ERR_VDB;
    }
    res = sb_image_init_volume(volume, a.width, a.height, a.depth, channels);
    if (!res && !(sb_sandbox_read(&box, got, sizeof(got)) &&
                  sb_sandbox_read(&box, volume->data, sb_image_float_count(volume) * sizeof(float)))) {
        sb_sandbox_finish(&box, why, sizeof(why));
        sb_error("%s: OpenVDB stopped half way: its process %s", path, why);
        res = SB_ERR_VDB;
    }
    sb_sandbox_finish(&box, nullptr, 0);
    if (res) {
        sb_image_finish(volume);
        return res;
    }
    sb_image_set_channel_names(volume, channel_order);
    for (int i = 0; attributes && i < a.attribute_count; i++) {
        got[i].name[sizeof(got[i].name) - 1] = '\0';
        got[i].value[sizeof(got[i].value) - 1] = '\0';
        attributes[i] = got[i];
    }
    if (attribute_count)
        *attribute_count = attributes ? a.attribute_count : 0;
    return SB_OK;
}
