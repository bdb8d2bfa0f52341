// Writes reference values for the Rust NanoVDB reader's tests, using the
// NanoVDB headers themselves (Debian package libnanovdb-dev, NanoVDB 32.4.2).
//
//   g++ -O2 -std=c++17 dump_reference.cpp -o dump_reference -lz
//   ./dump_reference FILE.nvdb GRID_NAME > FILE.GRID_NAME.ref
//
// Output lines (floats as the hex of their IEEE bits, so comparisons are exact):
//   name N / class C / bbox i0 j0 k0 i1 j1 k1 / wbbox x0 y0 z0 x1 y1 z1 (doubles' bits)
//   minmax MIN MAX / background B
//   v i j k VALUE                 for every voxel in the index bbox grown by 1
//   s x y z VALUE                 trilinear samples at pseudo-random index points
//   w x y z ix iy iz              worldToIndexF at pseudo-random world points
#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/IO.h>
#include <nanovdb/util/SampleFromVoxels.h>

#include <cinttypes>
#include <cstdio>
#include <cstring>

static uint32_t bits(float f)
{
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

static unsigned long long bits(double d)
{
    unsigned long long u;
    std::memcpy(&u, &d, 8);
    return u;
}

int main(int argc, char** argv)
{
    if (argc != 3) {
        std::fprintf(stderr, "usage: %s file.nvdb grid\n", argv[0]);
        return 2;
    }
    auto handle = nanovdb::io::readGrid(argv[1], argv[2]);
    const nanovdb::FloatGrid* grid = handle.grid<float>();
    if (!grid) {
        std::fprintf(stderr, "no float grid named %s\n", argv[2]);
        return 1;
    }
    const auto& tree = grid->tree();
    const auto bbox = tree.root().bbox();
    const auto wb = grid->worldBBox();
    float lo, hi;
    tree.extrema(lo, hi);
    std::printf("name %s\n", grid->gridName());
    std::printf("class %d\n", int(grid->gridClass()));
    std::printf("bbox %d %d %d %d %d %d\n", bbox.min()[0], bbox.min()[1], bbox.min()[2],
                bbox.max()[0], bbox.max()[1], bbox.max()[2]);
    std::printf("wbbox %016llx %016llx %016llx %016llx %016llx %016llx\n", bits(wb.min()[0]),
                bits(wb.min()[1]), bits(wb.min()[2]), bits(wb.max()[0]), bits(wb.max()[1]),
                bits(wb.max()[2]));
    std::printf("minmax %08x %08x\n", bits(lo), bits(hi));
    std::printf("background %08x\n", bits(tree.background()));
    for (int i = bbox.min()[0] - 1; i <= bbox.max()[0] + 1; ++i)
        for (int j = bbox.min()[1] - 1; j <= bbox.max()[1] + 1; ++j)
            for (int k = bbox.min()[2] - 1; k <= bbox.max()[2] + 1; ++k)
                std::printf("v %d %d %d %08x\n", i, j, k, bits(tree.getValue(nanovdb::Coord(i, j, k))));
    // A small LCG so the points are reproducible without <random>'s distributions.
    uint64_t state = 0x2545F4914F6CDD1DULL;
    auto next = [&state]() {
        state = state * 6364136223846793005ULL + 1442695040888963407ULL;
        return float((state >> 40) & 0xFFFFFF) / float(1 << 24);
    };
    using Sampler = nanovdb::SampleFromVoxels<nanovdb::FloatGrid::TreeType, 1, false>;
    Sampler sampler(tree);
    for (int n = 0; n < 200; ++n) {
        nanovdb::Vec3f p(bbox.min()[0] - 2 + next() * (bbox.dim()[0] + 4),
                         bbox.min()[1] - 2 + next() * (bbox.dim()[1] + 4),
                         bbox.min()[2] - 2 + next() * (bbox.dim()[2] + 4));
        std::printf("s %08x %08x %08x %08x\n", bits(p[0]), bits(p[1]), bits(p[2]), bits(sampler(p)));
    }
    for (int n = 0; n < 100; ++n) {
        nanovdb::Vec3f p(float(wb.min()[0] + (next() * 1.5 - 0.25) * (wb.max()[0] - wb.min()[0])),
                         float(wb.min()[1] + (next() * 1.5 - 0.25) * (wb.max()[1] - wb.min()[1])),
                         float(wb.min()[2] + (next() * 1.5 - 0.25) * (wb.max()[2] - wb.min()[2])));
        nanovdb::Vec3f q = grid->worldToIndexF(p);
        std::printf("w %08x %08x %08x %08x %08x %08x\n", bits(p[0]), bits(p[1]), bits(p[2]),
                    bits(q[0]), bits(q[1]), bits(q[2]));
    }
    return 0;
}
