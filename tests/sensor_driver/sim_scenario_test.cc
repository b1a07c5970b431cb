// Scenario files: the shipped ones load, are physically sensible (no footprints overlap) and have
// the content the paper's figures and the demo need; malformed ones give errors that name the
// file, line and key instead of crashing.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "sensor_driver/sim/describe.h"
#include "sensor_driver/sim/scenario.h"
#include "sensor_driver/sim/simulator.h"
#include "tests/support/test_env.h"
#include "base/angle.h"
#include "base/box.h"

namespace vtrack::sim {
namespace {

namespace fs = std::filesystem;
using vtrack::testing::ScratchDir;
using vtrack::testing::SourceDir;

std::string ScenarioPath(const std::string& name) {
  return SourceDir() + "/config/scenarios/" + name + ".yaml";
}

// Total signed heading change of a motion over [0, t_end], by summing wrapped steps.
double Turned(const VehicleMotion& m, double t_end) {
  double turned = 0.0, prev = m.At(0.0).yaw;
  for (double t = 0.01; t <= t_end + 1e-9; t += 0.01) {
    const double y = m.At(t).yaw;
    turned += AngleDiff(y, prev);
    prev = y;
  }
  return turned;
}

const SceneObject& ById(const Scenario& sc, std::int64_t id) {
  for (const auto& o : sc.scene.objects) {
    if (o.id == id) return o;
  }
  throw std::runtime_error("no object " + std::to_string(id));
}

TEST(ShippedScenariosTest, EveryFileLoadsIsCollisionFreeAndSimulates) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(SourceDir() + "/config/scenarios")) {
    if (e.path().extension() != ".yaml") continue;
    names.insert(e.path().stem().string());
    SCOPED_TRACE(e.path().string());
    const Scenario sc = LoadScenario(e.path().string());
    EXPECT_EQ(sc.name, e.path().stem().string());
    EXPECT_FALSE(sc.description.empty());
    // Vehicles never drive through each other, through clutter, or through the ego.
    for (const auto& ov : FindOverlaps(sc)) {
      ADD_FAILURE() << ov.a << " and " << ov.b << " overlap by " << ov.depth << " m at t = " << ov.t;
    }
    // Every sensor the scenario names builds, and a sweep of the default one runs.
    for (const auto& [name, p] : sc.sensors) EXPECT_EQ(p.Validate(), "") << name;
    Simulator sim(sc);
    vtrack::ladar_scan_t scan;
    vtrack::object_list_t truth;
    sim.MakeScan(sim.NumScans() / 2, sc.start_utime, 0, &scan, &truth);
    EXPECT_GT(scan.npoints, 50);
    EXPECT_EQ(truth.num_objects, static_cast<int>(sc.scene.objects.size()));
  }
  for (const char* required : {"paper_fig4_turn", "paper_fig5_follow_clutter",
                               "paper_fig6_noisy_follow", "urban_intersection",
                               "reversing_and_skid_steer", "stress"}) {
    EXPECT_TRUE(names.count(required)) << required;
  }
}

// Figure 4: one car turns 90 deg through the intersection in view of the waiting ego.
TEST(ShippedScenariosTest, Fig4CarTurnsNinetyDegreesInView) {
  const Scenario sc = LoadScenario(ScenarioPath("paper_fig4_turn"));
  const SceneObject& car = ById(sc, 1);
  ASSERT_TRUE(car.moving());
  EXPECT_NEAR(RadToDeg(Turned(*car.motion, sc.duration)), 90.0, 1.0);
  EXPECT_TRUE(sc.scene.ego.motion->IsStatic());
  // Well observed from before the turn (steering from t = 5.5 s) until after it (8.3 s).
  Simulator sim(sc);
  vtrack::ladar_scan_t scan;
  vtrack::object_list_t truth;
  for (int i = 0; i < sim.NumScans(); ++i) {
    const double t = sim.ScanOffsetUs(i) * 1e-6;
    if (t < 4.0 || t > 9.0) continue;  // it passes the sensor, out of the 180 deg view, at 9.5 s
    sim.MakeScan(i, 0, i, &scan, &truth);
    for (const auto& o : truth.objects) {
      if (o.id == 1) {
        EXPECT_GE(o.num_points, 10) << "t = " << t;
        EXPECT_TRUE(o.in_labelled_region) << "t = " << t;
      }
    }
  }
}

// Figure 5: the ego follows the car 8-25 m behind, seeing its rear (and not its sides) until it
// turns sharply right at the end.
TEST(ShippedScenariosTest, Fig5FollowsSeeingTheRearThenTheCarTurnsSharply) {
  const Scenario sc = LoadScenario(ScenarioPath("paper_fig5_follow_clutter"));
  const SceneObject& car = ById(sc, 1);
  EXPECT_NEAR(RadToDeg(Turned(*car.motion, sc.duration)), -90.0, 1.0);
  const LadarParams p = sc.Sensor();
  int rear_only = 0, samples = 0;
  for (double t = 0.0; t < 22.0; t += 0.25) {
    const Eigen::Vector2d sensor = (sc.scene.WorldFromBody(t) * p.BodyFromSensor()).translation().head<2>();
    const ObjectState s = sc.scene.StateOf(car, t);
    const double d = (s.center - sensor).norm();
    EXPECT_GT(d, 8.0);
    EXPECT_LT(d, 25.0);
    OrientedBox box;
    box.center = s.center;
    box.theta = s.yaw;
    box.length = car.length;
    box.width = car.width;
    const std::uint8_t faces = VisibleFaces(box, sensor, DegToRad(10.0));
    EXPECT_TRUE(faces & (1u << static_cast<int>(Face::kRear))) << "t = " << t;
    rear_only += faces == (1u << static_cast<int>(Face::kRear));
    ++samples;
  }
  EXPECT_GT(rear_only, 0.8 * samples);
  // Clutter: parked cars, poles, bushes and walls line the street.
  std::set<ObjectClass> classes;
  for (const auto& o : sc.scene.objects) classes.insert(o.object_class);
  for (ObjectClass c : {ObjectClass::kCar, ObjectClass::kVan, ObjectClass::kPole, ObjectClass::kBush,
                        ObjectClass::kWall}) {
    EXPECT_TRUE(classes.count(c)) << ObjectClassName(c);
  }
}

// Figure 6 is Figure 5's drive with far more noise.
TEST(ShippedScenariosTest, Fig6IsFig5WithHeavyNoise) {
  const Scenario a = LoadScenario(ScenarioPath("paper_fig5_follow_clutter"));
  const Scenario b = LoadScenario(ScenarioPath("paper_fig6_noisy_follow"));
  EXPECT_EQ(b.name, "paper_fig6_noisy_follow");
  ASSERT_EQ(a.scene.objects.size(), b.scene.objects.size());
  for (double t : {0.0, 11.0, 24.0, 29.0}) {
    for (std::size_t i = 0; i < a.scene.objects.size(); ++i) {
      EXPECT_EQ(a.scene.StateOf(a.scene.objects[i], t).center, b.scene.StateOf(b.scene.objects[i], t).center);
    }
    EXPECT_EQ(a.scene.EgoAt(t).axis_point, b.scene.EgoAt(t).axis_point);
  }
  const LadarParams pa = a.Sensor(), pb = b.Sensor();
  EXPECT_GE(pb.range_noise, 3 * pa.range_noise);
  EXPECT_GT(pb.dropout, 0.1);
  EXPECT_GT(pb.spurious, 0.01);
  EXPECT_GT(b.pose_noise.position, 0.0);
  EXPECT_EQ(a.pose_noise.position, 0.0);
}

TEST(ShippedScenariosTest, UrbanIntersectionHasEverythingTheDemoNeeds) {
  const Scenario sc = LoadScenario(ScenarioPath("urban_intersection"));
  EXPECT_NEAR(sc.duration, 60.0, 15.0);
  EXPECT_EQ(sc.Sensor().NumLayers(), 64);
  EXPECT_EQ(sc.Sensor("single_plane").NumLayers(), 1);
  int movers = 0, parked = 0, reversing = 0, skid = 0, turning = 0;
  std::set<ObjectClass> clutter;
  for (const auto& o : sc.scene.objects) {
    if (!IsVehicleClass(o.object_class)) {
      clutter.insert(o.object_class);
      continue;
    }
    if (!o.moving()) {
      ++parked;
      continue;
    }
    ++movers;
    skid += o.motion->params().kind == SteeringKind::kSkidSteer;
    bool rev = false;
    for (double t = 0; t < sc.duration; t += 0.1) rev |= o.motion->At(t).speed < -0.5;
    reversing += rev;
    turning += std::abs(Turned(*o.motion, sc.duration)) > DegToRad(45.0);
  }
  EXPECT_GE(movers, 5);
  EXPECT_GE(turning, 3);
  EXPECT_GE(reversing, 1);
  EXPECT_GE(skid, 1);
  EXPECT_GE(parked, 20);
  EXPECT_EQ(clutter, (std::set<ObjectClass>{ObjectClass::kWall, ObjectClass::kPole, ObjectClass::kBush}));
  EXPECT_GT((sc.scene.EgoAt(sc.duration).axis_point - sc.scene.EgoAt(0).axis_point).norm(), 50.0);
}

TEST(ShippedScenariosTest, ReversingAndSkidSteer) {
  const Scenario sc = LoadScenario(ScenarioPath("reversing_and_skid_steer"));
  int reversing = 0;
  std::set<double> skid_axes;
  bool turns_in_place = false;
  for (const auto& o : sc.scene.objects) {
    if (!o.moving()) continue;
    bool rev = false;
    for (double t = 0; t < sc.duration; t += 0.05) {
      const MotionState s = o.motion->At(t);
      rev |= s.speed < -0.5;
      turns_in_place |= s.speed == 0.0 && std::abs(s.yaw_rate) > 0.3;
    }
    reversing += rev && o.motion->params().kind == SteeringKind::kAckerman;
    if (o.motion->params().kind == SteeringKind::kSkidSteer) skid_axes.insert(o.rotation_axis_offset);
  }
  EXPECT_GE(reversing, 2);
  EXPECT_GE(skid_axes.size(), 2u);  // two skid-steers with different rotation axes
  EXPECT_TRUE(turns_in_place);
}

TEST(ShippedScenariosTest, StressHasTwoHundredVehiclesAndSixtyFourLayers) {
  const Scenario sc = LoadScenario(ScenarioPath("stress"));
  int vehicles = 0, moving = 0;
  for (const auto& o : sc.scene.objects) {
    vehicles += IsVehicleClass(o.object_class);
    moving += o.moving();
  }
  EXPECT_GE(vehicles, 200);
  EXPECT_GE(moving, 100);
  EXPECT_EQ(sc.Sensor().NumLayers(), 64);
}

// ------------------------------------------------------------------------------------------
// Malformed files

const char* kValid = R"(duration: 10
sensor: single_plane
ego:
  start: {x: 0, y: 0}
vehicles:
  - class: car
    start: {x: 10, y: 0}
    profile:
      - {t: 0, speed: 5}
)";

struct BadCase {
  const char* name;
  std::string yaml;
  std::string where;  // "file:line" or "file:line:col" suffix expected after the file name
  std::string what;   // substring of the message
};

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  if (at == std::string::npos) throw std::runtime_error("test bug: '" + from + "' not in template");
  return s.replace(at, from.size(), to);
}

void PrintTo(const BadCase& c, std::ostream* os) { *os << c.name; }

class BadScenarioTest : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadScenarioTest, ClearErrorNamingFileLineAndKey) {
  const BadCase& c = GetParam();
  const std::string dir = ScratchDir(std::string("bad_scenario_") + c.name);
  const std::string path = dir + "/bad.yaml";
  std::ofstream(path, std::ios::binary) << c.yaml;
  try {
    LoadScenario(path);
    FAIL() << "loaded a malformed scenario: " << c.name;
  } catch (const ScenarioError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path + c.where), std::string::npos) << msg;
    EXPECT_NE(msg.find(c.what), std::string::npos) << msg;
  }
}

std::vector<BadCase> BadCases() {
  const std::string v = kValid;
  return {
      {"unknown_key", Replace(v, "duration: 10", "durration: 10"), ":1:1:",
       "durration: unknown key (did you mean 'duration'?)"},
      {"not_a_number", Replace(v, "duration: 10", "duration: ten"), ":1:11:",
       "duration: expected a number, got 'ten'"},
      {"out_of_range", Replace(v, "duration: 10", "duration: -5"), ":1:11:",
       "duration = -5: must be in (0, 3600]"},
      {"not_finite", Replace(v, "duration: 10", "duration: .nan"), ":1:11:",
       "expected a finite number"},
      {"missing_required", Replace(v, "ego:\n  start: {x: 0, y: 0}\n", ""), ":1:1:",
       "ego: required key is missing"},
      {"yaml_syntax", Replace(v, "start: {x: 0, y: 0}", "start: {x: 0, y: [0}"), ":4:",
       "YAML syntax error"},
      {"time_goes_back", Replace(v, "- {t: 0, speed: 5}", "- {t: 2, speed: 5}\n      - {t: 1, speed: 3}"),
       ":10:", "vehicles[0].profile[1].t = 1: is earlier than the previous keyframe's t = 2"},
      {"steer_too_large", Replace(v, "{t: 0, speed: 5}", "{t: 0, speed: 5, steer_deg: 75}"), ":9:",
       "vehicles[0].profile[0].steer_deg = 75: must be in (-60, 60)"},
      {"yaw_rate_on_ackerman", Replace(v, "{t: 0, speed: 5}", "{t: 0, speed: 5, yaw_rate_deg: 5}"),
       ":9:", "an Ackerman vehicle is steered with steer_deg"},
      {"empty_keyframe", Replace(v, "{t: 0, speed: 5}", "{t: 0}"), ":9:",
       "a keyframe needs speed and/or steer_deg"},
      {"duplicate_id", v + "  - id: 4\n    start: {x: 20, y: 0}\n  - id: 4\n    start: {x: 30, y: 0}\n",
       ":12:", "vehicles[2].id = 4: is used twice"},
      {"duplicate_key", Replace(v, "duration: 10", "duration: 10\nduration: 12"), ":2:1:",
       "duration: key given twice"},
      {"unknown_preset", Replace(v, "sensor: single_plane", "sensor: s\nsensors:\n  s: {preset: lidar9}"),
       ":4:", "sensors.s.preset = lidar9: unknown preset"},
      {"elevations_order",
       Replace(v, "sensor: single_plane", "sensor: s\nsensors:\n  s: {elevations_deg: [1, 0.5]}"),
       ":4:", "elevations_deg[1] = 0.5: must be greater than the previous layer"},
      {"bad_mount", Replace(v, "sensor: single_plane", "sensor: s\nsensors:\n  s:\n    mount: {z: -1}"),
       ":5:", "mount.z = -1: must be in (0.05, 10]"},
      {"unknown_sensor", Replace(v, "sensor: single_plane", "sensor: lidar9"), ":2:",
       "is neither a key of `sensors` nor a built-in preset"},
      {"extends_missing", "extends: no_such_base\n" + v, ":1:", "no scenario 'no_such_base'"},
      {"top_level_list", "- a\n- b\n", ":1:", "a scenario file is a map"},
      {"empty_file", "", "", "a scenario file is a map"},
      {"not_a_list", "duration: 10\nsensor: single_plane\nego:\n  start: {x: 0, y: 0}\nvehicles: 3\n",
       ":5:", "vehicles: expected a list"},
      {"unknown_class", Replace(v, "class: car", "class: bus"), ":6:",
       "vehicles[0].class = bus: must be one of: car, van, truck, skid_steer"},
      {"wall_too_short", v + "walls:\n  - {from: [1, 1], to: [1, 1.05]}\n", ":11:",
       "from and to must be at least 0.1 m apart"},
      {"not_an_integer", Replace(v, "duration: 10", "duration: 10\nseed: 1.5"), ":2:7:",
       "seed: expected an integer, got '1.5'"},
      {"lane_spacing", v + "traffic:\n  - {kind: lane, count: 3, start: {x: 0, y: 9}, spacing: 2, speed: 3}\n",
       ":11:", "traffic[0].spacing = 2: must be at least the vehicle length"},
      {"front_axle_outside", Replace(v, "class: car", "class: car\n    wheelbase: 4.0\n    rear_axle_offset: 0"),
       ":6:", "puts the front axle outside the vehicle"},
      {"binary_garbage", std::string("\x01\x02\xff\xfe{[\0\0:\x7f", 11), "", ""},
  };
}

INSTANTIATE_TEST_SUITE_P(Cases, BadScenarioTest, ::testing::ValuesIn(BadCases()),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(ScenarioErrorsTest, MissingFileAndUnknownName) {
  try {
    LoadScenario("/nonexistent/dir/x.yaml");
    FAIL();
  } catch (const ScenarioError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/x.yaml: cannot read"), std::string::npos);
  }
  try {
    ResolveScenarioPath("no_such_scenario_name");
    FAIL();
  } catch (const ScenarioError& e) {
    EXPECT_NE(std::string(e.what()).find("no scenario 'no_such_scenario_name'"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("config/scenarios/no_such_scenario_name.yaml"), std::string::npos);
  }
  // A name resolves to the source tree's file; a path is taken as it is.
  EXPECT_TRUE(fs::equivalent(ResolveScenarioPath("stress"), ScenarioPath("stress")));
  EXPECT_EQ(ResolveScenarioPath(ScenarioPath("stress")), ScenarioPath("stress"));
}

TEST(ScenarioTest, ExtendsMergesMapsAndReplacesLists) {
  const std::string dir = ScratchDir("scenario_extends");
  std::ofstream(dir + "/base.yaml") << kValid << "poles:\n  - {x: 5, y: 5}\n  - {x: 6, y: 6}\n"
                                    << "sensors:\n  s: {preset: velodyne64, range_noise: 0.01}\n";
  std::ofstream(dir + "/derived.yaml")
      << "extends: base\nduration: 20\nsensors:\n  s: {dropout: 0.2}\npoles:\n  - {x: 9, y: 9}\n";
  const Scenario b = LoadScenario(dir + "/derived.yaml");
  EXPECT_EQ(b.name, "derived");
  EXPECT_DOUBLE_EQ(b.duration, 20.0);
  const LadarParams s = b.Sensor("s");
  EXPECT_EQ(s.NumLayers(), 64);          // from the base's preset
  EXPECT_DOUBLE_EQ(s.range_noise, 0.01);  // from the base
  EXPECT_DOUBLE_EQ(s.dropout, 0.2);       // from the derived file
  int poles = 0;
  for (const auto& o : b.scene.objects) poles += o.object_class == ObjectClass::kPole;
  EXPECT_EQ(poles, 1);  // lists replace

  // An error in the derived file is reported against the derived file.
  std::ofstream(dir + "/bad.yaml") << "extends: base\nduration: 20\nsensors:\n  s: {dropout: 2}\n";
  try {
    LoadScenario(dir + "/bad.yaml");
    FAIL();
  } catch (const ScenarioError& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/bad.yaml:4:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("dropout = 2"), std::string::npos) << e.what();
  }
  // A cycle is refused, not followed forever.
  std::ofstream(dir + "/a.yaml") << "extends: b\n";
  std::ofstream(dir + "/b.yaml") << "extends: a\n";
  EXPECT_THROW(LoadScenario(dir + "/a.yaml"), ScenarioError);
}

// Generators: a lane of vehicles one behind the other, a ring on its circle, rows with gaps.
TEST(ScenarioTest, GeneratorsPlaceVehicles) {
  const std::string dir = ScratchDir("scenario_generators");
  std::ofstream(dir + "/g.yaml") << R"(duration: 10
sensor: single_plane
ego:
  start: {x: -50, y: -50}
traffic:
  - {kind: lane, class: van, count: 4, start: {x: 100, y: 3, yaw_deg: 180}, spacing: 10, speed: 4}
  - {kind: ring, count: 6, center: [0, 40], radius: 15, speed: 5}
parked:
  - {x: 0, y: -10, yaw_deg: 90, count: 5, spacing: 3, direction_deg: 0, skip: [1, 3]}
)";
  const Scenario sc = LoadScenario(dir + "/g.yaml");
  ASSERT_EQ(sc.scene.objects.size(), 4u + 6u + 3u);
  // Lane: vans at x = 100, 110, 120, 130 (behind the first, against the heading), driving west.
  for (int k = 0; k < 4; ++k) {
    const SceneObject& o = sc.scene.objects[k];
    EXPECT_EQ(o.object_class, ObjectClass::kVan);
    EXPECT_NEAR(o.center.x(), 100.0 + 10.0 * k, 1e-9);
    const MotionState m = o.motion->At(2.0);
    EXPECT_NEAR(m.center.x(), 100.0 + 10.0 * k - 8.0, 1e-6);
    EXPECT_NEAR(m.center.y(), 3.0, 1e-6);
  }
  // Ring: every rear axle stays on the circle of radius 15, equally spaced.
  for (int k = 4; k < 10; ++k) {
    const SceneObject& o = sc.scene.objects[k];
    for (double t : {0.0, 3.3, 9.9}) {
      EXPECT_NEAR((o.motion->At(t).axis_point - Eigen::Vector2d(0, 40)).norm(), 15.0, 1e-6);
    }
  }
  // Row: positions 0, 6, 12 (indices 1 and 3 skipped).
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(sc.scene.objects[10 + k].center.x(), 6.0 * k, 1e-9);
    EXPECT_FALSE(sc.scene.objects[10 + k].moving());
  }
  std::set<std::int64_t> ids;
  for (const auto& o : sc.scene.objects) ids.insert(o.id);
  EXPECT_EQ(ids.size(), sc.scene.objects.size());  // ids are unique
}

}  // namespace
}  // namespace vtrack::sim
