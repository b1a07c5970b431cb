// Finding a sequence's files, and the packed layout: a .tar.zst of the point clouds unpacked once
// into the cache and checked against its .sha256. The archives are made by the test with tar.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "sensor_driver/kitti/kitti_layout.h"
#include "sensor_driver/kitti/kitti_sequence.h"
#include "tests/sensor_driver/kitti_synthetic.h"
#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"

namespace vtrack::kitti {
namespace {

namespace fs = std::filesystem;
using vtrack::testing::ReadFile;
using vtrack::testing::RunCommand;
using vtrack::testing::ScratchDir;

TEST(KittiLayoutTest, NormalisesSequenceNames) {
  EXPECT_EQ(NormaliseSequence("0"), "0000");
  EXPECT_EQ(NormaliseSequence("12"), "0012");
  EXPECT_EQ(NormaliseSequence("0020"), "0020");
  EXPECT_THROW(NormaliseSequence(""), KittiError);
  EXPECT_THROW(NormaliseSequence("12345"), KittiError);
  EXPECT_THROW(NormaliseSequence("-1"), KittiError);
  EXPECT_THROW(NormaliseSequence("1a"), KittiError);
}

TEST(KittiLayoutTest, DefaultCacheDirFollowsXdg) {
  const char* old = std::getenv("XDG_CACHE_HOME");
  const std::string saved = old ? old : "";
  setenv("XDG_CACHE_HOME", "/some/cache", 1);
  EXPECT_EQ(DefaultCacheDir(), "/some/cache/vtrack");
  if (old) {
    setenv("XDG_CACHE_HOME", saved.c_str(), 1);
  } else {
    unsetenv("XDG_CACHE_HOME");
  }
}

// The synthetic sequence with its velodyne/ folder packed as velodyne_0000.tar.zst beside the rest.
struct Packed {
  std::string dir, archive, cache;
};
Packed MakePacked(const std::string& name) {
  Packed p;
  p.dir = ScratchDir(name);
  vtrack::testing::SyntheticSequence s;
  s.dir = p.dir;
  s.num_frames = 3;
  s.objects = {vtrack::testing::SyntheticObject{}};
  s.objects[0].x0 = 12.0;
  s.Write();
  p.archive = p.dir + "/velodyne_0000.tar.zst";
  const std::string log = p.dir + "/tar.txt";
  EXPECT_EQ(RunCommand({"tar", "--zstd", "-cf", p.archive, "-C", p.dir, "velodyne"}, log), 0) << ReadFile(log);
  fs::remove_all(p.dir + "/velodyne");
  p.cache = p.dir + "/cache";
  return p;
}

std::string Sha256Of(const std::string& path, const std::string& scratch) {
  const std::string log = scratch + "/sha.txt";
  EXPECT_EQ(RunCommand({"sha256sum", path}, log), 0);
  return ReadFile(log).substr(0, 64);
}

TEST(KittiLayoutTest, UnpacksOnceAndVerifiesTheChecksum) {
  const Packed p = MakePacked("kitti_layout_pack");
  std::ofstream(p.archive + ".sha256") << Sha256Of(p.archive, p.dir) << "  velodyne_0000.tar.zst\n";
  std::vector<std::string> messages;
  const MessageSink sink = [&](const std::string& m) { messages.push_back(m); };

  const std::string velodyne = UnpackVelodyneArchive(p.archive, "0", p.cache, sink);
  EXPECT_TRUE(fs::is_regular_file(velodyne + "/000002.bin"));
  EXPECT_EQ(velodyne.rfind(p.cache + "/kitti/velodyne_0000.tar.zst-", 0), 0u) << velodyne;
  bool said_unpacking = false;
  for (const auto& m : messages) said_unpacking |= m.find("unpacking " + p.archive) != std::string::npos;
  EXPECT_TRUE(said_unpacking);
  // No partial folder is left behind.
  int entries = 0;
  for (const auto& e : fs::directory_iterator(p.cache + "/kitti")) {
    ++entries;
    EXPECT_EQ(e.path().string().find(".partial"), std::string::npos) << e.path();
  }
  EXPECT_EQ(entries, 1);

  // Second time: straight from the cache, nothing said, same place.
  messages.clear();
  EXPECT_EQ(UnpackVelodyneArchive(p.archive, "0000", p.cache, sink), velodyne);
  EXPECT_TRUE(messages.empty());

  // Through the Sequence: the packed layout is found and read.
  SequenceOptions o;
  o.dir = p.dir;
  o.poses_file = p.dir + "/poses.txt";
  o.cache_dir = p.cache;
  o.sink = sink;
  const Sequence seq(o);
  EXPECT_TRUE(seq.paths().packed);
  EXPECT_EQ(seq.num_frames(), 3);
  EXPECT_EQ(seq.GroundTruth(1).objects.at(0).num_points, 20);
}

TEST(KittiLayoutTest, RefusesAChecksumMismatch) {
  const Packed p = MakePacked("kitti_layout_badsum");
  std::ofstream(p.archive + ".sha256") << std::string(64, 'a') << "  velodyne_0000.tar.zst\n";
  try {
    UnpackVelodyneArchive(p.archive, "0000", p.cache, [](const std::string&) {});
    ADD_FAILURE() << "expected a checksum error";
  } catch (const KittiError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("checksum mismatch for " + p.archive), std::string::npos) << msg;
    EXPECT_NE(msg.find(std::string(64, 'a')), std::string::npos) << msg;
  }
  EXPECT_FALSE(fs::exists(p.cache + "/kitti/velodyne_0000.tar.zst-aaaaaaaaaaaaaaaa"));
  // A malformed checksum file is named.
  std::ofstream(p.archive + ".sha256") << "xyz\n";
  try {
    UnpackVelodyneArchive(p.archive, "0000", p.cache, [](const std::string&) {});
    ADD_FAILURE() << "expected an error";
  } catch (const KittiError& e) {
    EXPECT_NE(std::string(e.what()).find(p.archive + ".sha256:1"), std::string::npos) << e.what();
  }
}

TEST(KittiLayoutTest, CorruptArchiveOrWrongContents) {
  const std::string dir = ScratchDir("kitti_layout_corrupt");
  const std::string archive = dir + "/velodyne_0000.tar.zst";
  std::ofstream(archive) << "this is not a zstd stream";
  try {
    UnpackVelodyneArchive(archive, "0000", dir + "/cache", [](const std::string&) {});
    ADD_FAILURE() << "expected an error";
  } catch (const KittiError& e) {
    EXPECT_NE(std::string(e.what()).find("unpacking " + archive + " failed"), std::string::npos) << e.what();
  }
  // A valid archive of another sequence.
  const Packed p = MakePacked("kitti_layout_other");
  try {
    UnpackVelodyneArchive(p.archive, "0001", p.cache, [](const std::string&) {});
    ADD_FAILURE() << "expected an error";
  } catch (const KittiError& e) {
    EXPECT_NE(std::string(e.what()).find("holds no velodyne/0001/"), std::string::npos) << e.what();
  }
  for (const auto& e : fs::directory_iterator(p.cache + "/kitti")) ADD_FAILURE() << "left behind: " << e.path();
}

// The standard layout may be given as the folder that holds training/.
TEST(KittiLayoutTest, FindsTheTrainingSubfolder) {
  const std::string top = ScratchDir("kitti_layout_training");
  vtrack::testing::SyntheticSequence s;
  s.dir = top + "/training";
  s.num_frames = 2;
  s.Write();
  const SequencePaths p = LocateSequence(top, "0000", s.dir + "/poses.txt", "", "", [](const std::string&) {});
  EXPECT_EQ(p.root, s.dir);
  EXPECT_EQ(p.velodyne_dir, s.dir + "/velodyne/0000");
  EXPECT_EQ(p.calib_file, s.dir + "/calib/0000.txt");
  EXPECT_EQ(p.label_file, s.dir + "/label_02/0000.txt");
  EXPECT_FALSE(p.packed);
}

}  // namespace
}  // namespace vtrack::kitti
