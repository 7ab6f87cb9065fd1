// The frame: the packaged OpenVDB, OpenImageIO and TBB link and do their basic job here, so
// that bake/ and vdbtrace/ can stand on them. Files go to a fresh temporary folder.
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <openvdb/openvdb.h>
#include <tbb/parallel_reduce.h>
#include <tbb/blocked_range.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <string>

namespace {

namespace fs = std::filesystem;

fs::path freshFolder()
{
    const fs::path dir = fs::temp_directory_path() /
                         ("pine-frame-" + std::to_string(std::random_device{}()));
    fs::create_directories(dir);
    return dir;
}

TEST(Frame, OpenVdbWritesAndReadsAFogVolume)
{
    openvdb::initialize();
    const fs::path dir = freshFolder();
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("density");
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->getAccessor().setValue(openvdb::Coord(1, 2, 3), 0.5f);
    openvdb::io::File((dir / "g.vdb").string()).write({grid});
    openvdb::io::File in((dir / "g.vdb").string());
    in.open();
    auto back = openvdb::gridPtrCast<openvdb::FloatGrid>(in.readGrid("density"));
    ASSERT_TRUE(back);
    EXPECT_FLOAT_EQ(back->tree().getValue(openvdb::Coord(1, 2, 3)), 0.5f);
    fs::remove_all(dir);
}

TEST(Frame, OpenImageIoWritesExrAndPng)
{
    const fs::path dir = freshFolder();
    OIIO::ImageBuf image(OIIO::ImageSpec(4, 3, 4, OIIO::TypeDesc::FLOAT));
    const float colour[4] = {0.25f, 0.5f, 1.0f, 1.0f};
    OIIO::ImageBufAlgo::fill(image, colour);
    for (const char* name : {"i.exr", "i.png"}) {
        ASSERT_TRUE(image.write((dir / name).string())) << image.geterror();
        OIIO::ImageBuf back((dir / name).string());
        ASSERT_TRUE(back.read()) << back.geterror();
        EXPECT_EQ(back.spec().width, 4);
        EXPECT_NEAR(back.getchannel(1, 1, 0, 1), 0.5f, 0.01f);
    }
    fs::remove_all(dir);
}

TEST(Frame, TbbReducesInParallel)
{
    const long sum = tbb::parallel_reduce(
        tbb::blocked_range<long>(0, 100000), 0L,
        [](const tbb::blocked_range<long>& r, long acc) {
            for (long i = r.begin(); i != r.end(); ++i) acc += i;
            return acc;
        },
        [](long a, long b) { return a + b; });
    EXPECT_EQ(sum, 100000L * 99999L / 2);
}

}  // namespace
