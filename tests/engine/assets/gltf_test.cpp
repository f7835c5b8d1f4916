// glTF round trip and error messages for engine/assets.
#include <engine/assets/gltf.hpp>

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;
using engine::assets::MeshData;

namespace {

fs::path temp_dir() {
    fs::path p = fs::temp_directory_path() /
                 ("assets_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
                  ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(p);
    return p;
}

MeshData quad(const std::string& name, glm::dvec3 origin) {
    MeshData m;
    m.name = name;
    m.origin = origin;
    m.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    m.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    m.uvs = {0, 0, 1, 0, 1, 1, 0, 1};
    m.indices = {0, 1, 2, 0, 2, 3};
    return m;
}

}  // namespace

TEST(Gltf, WriteThenReadBackKeepsEveryAttribute) {
    const fs::path dir = temp_dir();
    const std::string path = (dir / "two.glb").string();
    std::vector<MeshData> meshes{quad("a", glm::dvec3(0.0)), quad("b", glm::dvec3(10.0, 0.0, 0.0))};
    ASSERT_TRUE(engine::assets::write_glb(path, meshes).ok());
    EXPECT_FALSE(fs::exists(path + ".tmp"));

    std::vector<MeshData> back;
    const auto status = engine::assets::read_gltf(path, back);
    ASSERT_TRUE(status.ok()) << status.message;
    ASSERT_EQ(back.size(), 2u);
    EXPECT_EQ(back[0].name, "a");
    EXPECT_EQ(back[0].positions, meshes[0].positions);
    EXPECT_EQ(back[0].normals, meshes[0].normals);
    EXPECT_EQ(back[0].uvs, meshes[0].uvs);
    EXPECT_EQ(back[0].indices, meshes[0].indices);
    // The second mesh's origin became a node translation, applied on reading.
    EXPECT_FLOAT_EQ(back[1].positions[3], 11.0f);
    fs::remove_all(dir);
}

TEST(Gltf, MissingFileNamesTheFile) {
    std::vector<MeshData> out;
    const auto status = engine::assets::read_gltf("/nonexistent/tunnel.glb", out);
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.message.find("/nonexistent/tunnel.glb"), std::string::npos) << status.message;
    EXPECT_NE(status.message.find("cannot open"), std::string::npos) << status.message;
}

TEST(Gltf, GarbageIsRejectedWithTheFileName) {
    const fs::path dir = temp_dir();
    const std::string path = (dir / "garbage.glb").string();
    std::ofstream(path, std::ios::binary) << "glTF this is not a real binary glTF";
    std::vector<MeshData> out;
    const auto status = engine::assets::read_gltf(path, out);
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.message.find("garbage.glb"), std::string::npos) << status.message;
    EXPECT_TRUE(out.empty());
    fs::remove_all(dir);
}

TEST(Gltf, BadIndexIsRefusedAndNoFileIsLeft) {
    const fs::path dir = temp_dir();
    const std::string path = (dir / "bad.glb").string();
    MeshData m = quad("broken", glm::dvec3(0.0));
    m.indices[4] = 99;
    const auto status = engine::assets::write_glb(path, std::vector<MeshData>{m});
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.message.find("index 4 = 99 out of range"), std::string::npos) << status.message;
    EXPECT_NE(status.message.find("'broken'"), std::string::npos) << status.message;
    EXPECT_FALSE(fs::exists(path));
    EXPECT_FALSE(fs::exists(path + ".tmp"));
    fs::remove_all(dir);
}

TEST(Gltf, UnwritableDirectoryIsAnError) {
    const auto status =
        engine::assets::write_glb("/nonexistent-dir/out.glb", std::vector<MeshData>{quad("a", glm::dvec3(0.0))});
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.message.find("/nonexistent-dir/out.glb"), std::string::npos) << status.message;
}
