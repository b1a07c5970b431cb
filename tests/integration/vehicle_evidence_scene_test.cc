// The vehicle evidence on a simulated 64-beam street (the real executables: vtrack-sim-log,
// vtrack-tracker): lamp posts never become vehicles, a garden wall seldom, and a parked car the
// ego drives past, seen along one side, does; a hedge row and a tree still do at times (the
// disabled case); recording the fitting set's rows changes no track. The truth comes from the
// simulator's GROUND_TRUTH (every object, clutter included), not from the tracker.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/log_reader.h"
#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"
#include "vtrack/object_list_t.hpp"
#include "vtrack/track_list_t.hpp"

namespace vtrack::testing {
namespace {

// The ego drives north at 3 m/s past (west) a 30 m garden wall 2 m high, (east) a hedge row of
// eleven 1.4 m bushes, a parked car and (west, further on) a tree: a bush 5 m across and 7 m high
// (the simulator's objects are prisms; a crown down to the ground is the hard case, with no
// trunk and no free space under it), and two lamp posts.
constexpr const char* kScenario = R"(description: "vehicle evidence: clutter beside one parked car"
duration: 16
seed: 3
sensor: velodyne64
sensors:
  velodyne64:
    preset: velodyne64
truth:
  labelled_radius: 60
  min_points: 5
ego:
  start: {x: 0.0, y: -25.0, yaw_deg: 90}
  wheelbase: 2.8
  profile:
    - {t: 0, speed: 3.0, steer_deg: 0}
parked:
  - {class: car, x: 4.6, y: 5.0, yaw_deg: 90}
walls:
  - {from: [-6.5, -20], to: [-6.5, 10], height: 2.0}
bushes:
  - {x: 6.5, y: -22.0, count: 11, spacing: 1.3, direction_deg: 90, radius: 0.7, height: 1.4}
  - {x: -9.0, y: 22.0, radius: 2.5, height: 7.0}
poles:
  - {x: 4.0, y: -5.0}
  - {x: -4.5, y: 15.0}
)";

template <class Msg>
std::vector<Msg> Read(const std::string& path, const std::string& channel) {
  std::vector<Msg> out;
  lcm_util::LogReader r(path);
  while (const lcm::LogEvent* ev = r.Next()) {
    if (ev->channel != channel) continue;
    Msg m;
    EXPECT_EQ(lcm_util::Decode(ev->data, static_cast<std::size_t>(ev->datalen), &m),
              lcm_util::DecodeError::kNone);
    out.push_back(std::move(m));
  }
  return out;
}

// Distance from (x, y) to the footprint of truth object o (an oriented rectangle).
double DistanceToFootprint(const object_t& o, double x, double y) {
  const double c = std::cos(o.yaw), s = std::sin(o.yaw);
  const double dx = x - o.x, dy = y - o.y;
  const double u = std::abs(c * dx + s * dy) - 0.5 * o.length;
  const double v = std::abs(-s * dx + c * dy) - 0.5 * o.width;
  return std::hypot(std::max(u, 0.0), std::max(v, 0.0));
}

enum Kind { kNone = -1, kWall, kHedge, kTree, kPost, kNumKinds };
const char* const kKindName[] = {"the wall", "the hedge row", "the tree", "a post"};

Kind KindOf(const object_t& o) {
  if (o.object_class == object_t::CLASS_WALL) return kWall;
  if (o.object_class == object_t::CLASS_POLE) return kPost;
  if (o.object_class == object_t::CLASS_BUSH) return o.length > 3.0 ? kTree : kHedge;
  return kNone;
}

// Per kind of clutter: confirmed track reports on it, and those classed vehicle; the car: scans
// it is well seen (20 returns or more), and those with a vehicle track on it.
struct SceneCounts {
  int on[kNumKinds] = {}, vehicle_on[kNumKinds] = {};
  int car_seen = 0, car_vehicle = 0;
};

// The street's log and its tracks (evidence_csv: also the tracker's --evidence-csv) in dir.
void TrackStreet(const std::string& dir, const std::string& evidence_csv = "") {
  const std::string scenario = dir + "/street.yaml", run = dir + "/run.lcm", tracks = dir + "/tracks.lcm";
  std::ofstream(scenario) << kScenario;
  EXPECT_EQ(RunCommand({BinDir() + "/vtrack-sim-log", "--scenario", scenario, "--out", run, "-q"},
                       dir + "/sim.txt"), 0) << ReadFile(dir + "/sim.txt");
  std::vector<std::string> argv = {BinDir() + "/vtrack-tracker", "--input", run, "--output", tracks, "-q"};
  if (!evidence_csv.empty()) argv.insert(argv.end(), {"--evidence-csv", evidence_csv});
  EXPECT_EQ(RunCommand(argv, dir + "/tracker.txt"), 0) << ReadFile(dir + "/tracker.txt");
}

// The street tracked once per process, without (plain) or with the fitting set's rows recorded
// (dir/evidence.csv), each by the first test that needs it: the tests below share the two runs
// (each a 16 s 64-beam lap, the longest part of this test under the sanitizers). A run that
// fails is reported by that first test; the others then find its files missing or short.
const std::string& PlainStreetDir() {
  static const std::string dir = [] {
    const std::string d = ScratchDir("vehicle_evidence_plain");
    TrackStreet(d);
    return d;
  }();
  return dir;
}

const std::string& RecordedStreetDir() {
  static const std::string dir = [] {
    const std::string d = ScratchDir("vehicle_evidence_recorded");
    TrackStreet(d, d + "/evidence.csv");
    return d;
  }();
  return dir;
}

SceneCounts RunStreet() {
  SceneCounts n;
  const std::string& dir = PlainStreetDir();
  const std::string run = dir + "/run.lcm", tracks = dir + "/tracks.lcm";
  const auto truth = Read<object_list_t>(run, "GROUND_TRUTH");
  const auto lists = Read<track_list_t>(tracks, "TRACKS");
  EXPECT_FALSE(lists.empty());

  std::size_t k = 0;
  for (const track_list_t& list : lists) {
    while (k < truth.size() && truth[k].utime < list.utime) ++k;
    if (k == truth.size() || truth[k].utime != list.utime) continue;
    const object_list_t& gt = truth[k];
    const object_t* car = nullptr;
    for (const object_t& o : gt.objects) {
      if (o.object_class == object_t::CLASS_CAR) car = &o;
    }
    if (car == nullptr) {
      ADD_FAILURE() << "no car in the truth at " << list.utime;
      return n;
    }
    for (const track_t& t : list.tracks) {
      if (t.status == track_t::STATUS_TENTATIVE) continue;
      if (std::hypot(t.x - car->x, t.y - car->y) < 4.0) continue;  // on (a piece of) the car
      for (const object_t& o : gt.objects) {
        const Kind kind = KindOf(o);
        if (kind == kNone || DistanceToFootprint(o, t.x, t.y) > 1.5) continue;
        ++n.on[kind];
        if (t.object_class == track_t::CLASS_VEHICLE) ++n.vehicle_on[kind];
        break;
      }
    }
    // The car well seen (20 returns or more): some track on it is a vehicle.
    if (car->num_points < 20) continue;
    ++n.car_seen;
    for (const track_t& t : list.tracks) {
      if (t.status != track_t::STATUS_TENTATIVE && t.object_class == track_t::CLASS_VEHICLE &&
          std::hypot(t.x - car->x, t.y - car->y) < 2.0) {
        ++n.car_vehicle;
        break;
      }
    }
  }
  return n;
}

TEST(VehicleEvidenceTest, PostsNeverBecomeVehiclesAParkedCarSeenAlongOneSideDoes) {
  const SceneCounts n = RunStreet();
  // The scene is made so that the clutter is tracked (else the test would prove nothing).
  for (const Kind kind : {kWall, kHedge, kTree, kPost}) EXPECT_GT(n.on[kind], 20) << kKindName[kind];
  EXPECT_EQ(n.vehicle_on[kPost], 0) << "reports on a post classed vehicle, of " << n.on[kPost];
  // The wall: rarely (none of its 148 reports today; 2 with an earlier model, where a piece of it
  // was first seen end-on).
  EXPECT_LE(n.vehicle_on[kWall] * 20, n.on[kWall]) << n.vehicle_on[kWall] << " of " << n.on[kWall];
  ASSERT_GT(n.car_seen, 50);
  // Evidence accumulates: the first scans of the car start at the prior, so not all of them.
  EXPECT_GE(n.car_vehicle, n.car_seen * 3 / 4) << n.car_vehicle << " of " << n.car_seen << " scans";
}

// The fitting set's rows (--evidence-csv) against the published TRACKS of the same run: every
// row names a track of that scan's list, at its reported centre, and the list's
// vehicle_probability is the sigmoid of the row's accumulated log-odds.
TEST(VehicleEvidenceTest, EvidenceRowsAgreeWithThePublishedTracks) {
  const std::string& dir = RecordedStreetDir();
  std::map<std::pair<std::int64_t, std::int64_t>, track_t> published;
  for (const track_list_t& list : Read<track_list_t>(dir + "/tracks.lcm", "TRACKS")) {
    for (const track_t& t : list.tracks) published[{list.utime, t.id}] = t;
  }
  std::ifstream in(dir + "/evidence.csv");
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  std::vector<std::string> header;
  for (std::stringstream ss(line); std::getline(ss, line, ',');) header.push_back(line);
  ASSERT_GE(header.size(), 8u);
  EXPECT_EQ(header[0], "utime");
  EXPECT_EQ(header[1], "track_id");
  EXPECT_EQ(header[2], "x");
  EXPECT_EQ(header[3], "y");
  EXPECT_EQ(header.back(), "log_odds");
  int rows = 0, deleted = 0;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    for (std::stringstream ss(line); std::getline(ss, line, ',');) f.push_back(line);
    ASSERT_EQ(f.size(), header.size()) << "row " << rows;
    ++rows;
    if (f[2] == "nan") {  // a duplicate the same scan's life cycle deleted: not reported
      EXPECT_EQ(published.count({std::stoll(f[0]), std::stoll(f[1])}), 0u);
      ++deleted;
      continue;
    }
    const auto it = published.find({std::stoll(f[0]), std::stoll(f[1])});
    ASSERT_NE(it, published.end()) << "row " << rows << ": no such track in TRACKS";
    EXPECT_NEAR(std::stod(f[2]), it->second.x, 1e-4);
    EXPECT_NEAR(std::stod(f[3]), it->second.y, 1e-4);
    const double p = 1.0 / (1.0 + std::exp(-std::stod(f.back())));
    EXPECT_NEAR(it->second.vehicle_probability, p, 1e-5);
  }
  EXPECT_GT(rows, 1000);
  EXPECT_LT(deleted * 20, rows) << deleted << " of " << rows;
}

// Recording the fitting set's rows (--evidence-csv) measures features no model of the defaults
// uses (roughness); the tracks must not notice: the same TRACKS, field for field, as without.
TEST(VehicleEvidenceTest, RecordingTheRowsLeavesTheTracksAsTheyAre) {
  const std::string& plain = PlainStreetDir();
  const std::string& recorded = RecordedStreetDir();
  const auto a = Read<track_list_t>(plain + "/tracks.lcm", "TRACKS");
  const auto b = Read<track_list_t>(recorded + "/tracks.lcm", "TRACKS");
  ASSERT_GT(a.size(), 100u);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].utime, b[k].utime);
    ASSERT_EQ(a[k].tracks.size(), b[k].tracks.size()) << "list " << k;
    for (std::size_t j = 0; j < a[k].tracks.size(); ++j) {
      const track_t& ta = a[k].tracks[j];
      const track_t& tb = b[k].tracks[j];
      EXPECT_EQ(ta.id, tb.id);
      EXPECT_EQ(ta.x, tb.x);
      EXPECT_EQ(ta.y, tb.y);
      EXPECT_EQ(ta.object_class, tb.object_class);
      EXPECT_EQ(ta.vehicle_probability, tb.vehicle_probability) << "list " << k << ", track " << ta.id;
    }
  }
}

// Fails today, kept to be run by hand (--gtest_also_run_disabled_tests): pieces of the hedge row
// (segments of 1-4 m, car height, 20-40 m away) gain vehicle evidence (200 of 301 confirmed
// reports on it classed vehicle); the tree (0 of 184) and the wall (0 of 156) do not
// (docs/design.md, section 4.10a).
// Their returns scatter 3-8 cm off a surface against the car's 1 cm (the roughness feature), but
// the shipped evidence model predates that feature (docs/design.md, section 4.10a).
TEST(VehicleEvidenceTest, DISABLED_WallHedgeRowAndTreeNeverBecomeVehicles) {
  const SceneCounts n = RunStreet();
  for (const Kind kind : {kWall, kHedge, kTree}) {
    std::cout << kKindName[kind] << ": " << n.vehicle_on[kind] << " of " << n.on[kind]
              << " reports classed vehicle\n";
    EXPECT_GT(n.on[kind], 20) << kKindName[kind];
    EXPECT_EQ(n.vehicle_on[kind], 0) << "reports on " << kKindName[kind] << " classed vehicle, of "
                                     << n.on[kind];
  }
}

}  // namespace
}  // namespace vtrack::testing
