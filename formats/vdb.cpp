// The one C++ file of skybake, since OpenVDB has no C API: the helper
// program skybake-vdb's tasks (vdb_helper.h), the only code that runs
// OpenVDB. No exception leaves this file.
//
// The writer serialises into memory and answers the bytes, which the
// caller writes (so that a full disk is reported with the system's
// reason, and the random UUID OpenVDB puts in the header is replaced with
// one derived from the content). The reader parses a file whose structure
// the caller has checked (vdb.c), checking each grid's shape in its
// metadata before it reads the grid.
#include <openvdb/io/Archive.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <sstream>
#include <string>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

extern "C" {
#include "io.h"
#include "log.h"
#include "sandbox.h"
#include "vdb_helper.h"
}

static_assert(openvdb::OPENVDB_FILE_VERSION == SB_VDB_FILE_VERSION,
              "vdb_helper.h's file version is not the OpenVDB this builds with");

namespace
{

constexpr int kLeafDim = openvdb::FloatTree::LeafNodeType::DIM; // 8

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

bool looks_like_uuid(const std::string &bytes, size_t at)
{
    if (bytes.size() < at + SB_VDB_UUID_SIZE)
        return false;
    for (size_t i = 0; i < SB_VDB_UUID_SIZE; i++) {
        char c = bytes[at + i];
        bool dash = i == 8 || i == 13 || i == 18 || i == 23;
        if (dash ? c != '-' : !std::isxdigit(static_cast<unsigned char>(c)))
            return false;
    }
    return true;
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

// The volume's grids, serialised, with the caller's UUID.
enum sb_result write_volume(const sb_vdb_request &job, const sb_image *volume, std::string *bytes)
{
    try {
        openvdb::initialize();
        openvdb::GridCPtrVec grids;
        openvdb::MetaMap file_meta;
        for (int a = 0; a < job.attribute_count; a++)
            file_meta.insertMeta(job.attributes[a].name, openvdb::StringMetadata(job.attributes[a].value));
        for (uint32_t c = 0; c < volume->channel_count; c++) {
            openvdb::FloatGrid::Ptr grid = channel_grid(volume, c);
            grid->setName(volume->channel_names[c]);
            grid->setGridClass(openvdb::GRID_FOG_VOLUME);
            grid->setSaveFloatAsHalf(true);
            grid->setTransform(texture_transform(volume->width, volume->height, volume->depth));
            for (int a = 0; a < job.attribute_count; a++)
                grid->insertMeta(job.attributes[a].name, openvdb::StringMetadata(job.attributes[a].value));
            grids.push_back(grid);
        }
        std::ostringstream os(std::ios_base::out | std::ios_base::binary);
        BufferWriter writer;
        writer.setCompression(openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
        writer.write_to(os, grids, file_meta);
        *bytes = os.str();
    } catch (const std::exception &e) {
        sb_error("%s: OpenVDB cannot write the volume: %s", job.path, e.what());
        return SB_ERR_VDB;
    }
    if (!looks_like_uuid(*bytes, SB_VDB_UUID_OFFSET)) {
        sb_error("%s: OpenVDB wrote a header this build does not know (no UUID at byte %d)", job.path,
                 SB_VDB_UUID_OFFSET);
        return SB_ERR_VDB;
    }
    bytes->replace(SB_VDB_UUID_OFFSET, SB_VDB_UUID_SIZE, job.uuid, SB_VDB_UUID_SIZE);
    return SB_OK;
}

// The helper's side of sb_vdb_write: the volume's floats mapped from the
// caller's memory file, its shape checked against the file's size.
int write_task(int out, const sb_vdb_request &job)
{
    sb_vdb_answer a = {};
    a.magic = SB_VDB_MAGIC;
    sb_sandbox_capture_log(a.message, sizeof(a.message));
    sb_image volume = job.volume;
    volume.data = nullptr;
    uint64_t floats = 0;
    struct stat st;
    bool shaped = volume.width && volume.height && volume.depth && volume.channel_count &&
                  volume.channel_count <= SB_IMAGE_MAX_CHANNELS && volume.levels <= 1 && job.attribute_count >= 0 &&
                  job.attribute_count <= SB_FILE_MAX_ATTRIBUTES;
    if (shaped) {
        floats = sb_image_float_count(&volume);
        shaped = fstat(SB_SANDBOX_FILE_FD, &st) == 0 && uint64_t(st.st_size) == floats * sizeof(float);
    }
    void *mapped =
        shaped ? mmap(nullptr, floats * sizeof(float), PROT_READ, MAP_PRIVATE, SB_SANDBOX_FILE_FD, 0) : MAP_FAILED;
    std::string bytes;
    if (mapped == MAP_FAILED) {
        sb_error("%s: the volume's %ux%ux%u voxels of %u channels are not what its process was given", job.path,
                 volume.width, volume.height, volume.depth, volume.channel_count);
        a.result = SB_ERR_VDB;
    } else {
        volume.data = static_cast<float *>(mapped);
        for (uint32_t c = 0; c < volume.channel_count; c++)
            volume.channel_names[c][SB_CHANNEL_NAME_MAX - 1] = '\0';
        a.result = write_volume(job, &volume, &bytes);
        munmap(mapped, floats * sizeof(float));
    }
    a.size = a.result ? 0 : bytes.size();
    bool ok = sb_write_all(out, &a, sizeof(a));
    if (!a.result && ok)
        ok = sb_write_all(out, bytes.data(), bytes.size());
    return ok ? 0 : 1;
}

// ---- reading: OpenVDB parses ---------------------------------------------------------------

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

// The helper's side of sb_vdb_read: the file is the caller's descriptor.
int read_task(int out, const sb_vdb_request &job)
{
    sb_vdb_answer a = {};
    a.magic = SB_VDB_MAGIC;
    sb_sandbox_capture_log(a.message, sizeof(a.message));
    char file_name[64];
    std::snprintf(file_name, sizeof(file_name), "/proc/self/fd/%d", SB_SANDBOX_FILE_FD);
    sb_image volume = {};
    sb_attribute attributes[SB_FILE_MAX_ATTRIBUTES] = {};
    int attribute_count = 0;
    // One thread: the CPU-time limit then bounds the wall time too.
    tbb::task_arena arena(1);
    arena.execute([&] {
        a.result =
            read_grids(job.path, file_name, job.channel_order, job.max_voxels, &volume, attributes, &attribute_count);
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

} // namespace

extern "C" int sb_vdb_task(int out, const void *request, size_t size)
{
    // The request is large (the volume's names); off the stack.
    std::unique_ptr<sb_vdb_request> job(new (std::nothrow) sb_vdb_request());
    if (!job || size != sizeof(*job))
        return 2;
    std::memcpy(job.get(), request, sizeof(*job));
    job->path[sizeof(job->path) - 1] = '\0';
    job->channel_order[sizeof(job->channel_order) - 1] = '\0';
    job->uuid[SB_VDB_UUID_SIZE] = '\0';
    for (sb_attribute &attribute : job->attributes) {
        attribute.name[sizeof(attribute.name) - 1] = '\0';
        attribute.value[sizeof(attribute.value) - 1] = '\0';
    }
    return job->task == SB_VDB_READ ? read_task(out, *job) : job->task == SB_VDB_WRITE ? write_task(out, *job) : 2;
}
