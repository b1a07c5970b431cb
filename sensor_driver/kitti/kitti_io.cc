#include "sensor_driver/kitti/kitti_io.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string_view>

#include "base/angle.h"
#include "vtrack/object_t.hpp"

namespace vtrack::kitti {
namespace {

// "file:line: what 'value'" — the shape of every parse error.
[[noreturn]] void Fail(const std::string& path, int line, const std::string& what) {
  std::ostringstream os;
  os << path;
  if (line > 0) os << ":" << line;
  os << ": " << what;
  throw KittiError(os.str());
}

std::ifstream OpenText(const std::string& path, const char* what) {
  std::ifstream in(path);
  if (!in) throw KittiError(std::string("cannot open ") + what + " file " + path + ": " +
                            std::strerror(errno));
  return in;
}

std::vector<std::string_view> Split(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    std::size_t j = i;
    while (j < s.size() && !std::isspace(static_cast<unsigned char>(s[j]))) ++j;
    if (j > i) out.push_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

bool IsBlank(std::string_view s) {
  for (char c : s) {
    if (!std::isspace(static_cast<unsigned char>(c))) return false;
  }
  return true;
}

// Parses a finite double; the whole token must be a number.
double ParseDouble(std::string_view tok, const std::string& path, int line, const char* field) {
  double v = 0.0;
  const char* first = tok.data();
  const char* last = tok.data() + tok.size();
  if (!tok.empty() && tok.front() == '+') ++first;  // from_chars refuses a leading '+'
  const auto [ptr, ec] = std::from_chars(first, last, v);
  if (ec != std::errc() || ptr != last) {
    Fail(path, line, std::string("bad number for ") + field + ": '" + std::string(tok) + "'");
  }
  if (!std::isfinite(v)) {
    Fail(path, line, std::string("non-finite value for ") + field + ": '" + std::string(tok) + "'");
  }
  return v;
}

int ParseInt(std::string_view tok, const std::string& path, int line, const char* field) {
  int v = 0;
  const char* first = tok.data();
  const char* last = tok.data() + tok.size();
  const auto [ptr, ec] = std::from_chars(first, last, v);
  if (ec != std::errc() || ptr != last) {
    Fail(path, line, std::string("bad integer for ") + field + ": '" + std::string(tok) + "'");
  }
  return v;
}

// Integer-valued field written as a number (OXTS writes "4" but some tools write "4.0").
int ParseIntegral(std::string_view tok, const std::string& path, int line, const char* field) {
  const double d = ParseDouble(tok, path, line, field);
  if (d != std::floor(d) || std::abs(d) > 1e9) {
    Fail(path, line, std::string("expected an integer for ") + field + ": '" + std::string(tok) + "'");
  }
  return static_cast<int>(d);
}

Eigen::Matrix3d Orthonormalised(const Eigen::Matrix3d& r) {
  return Eigen::Quaterniond(r).normalized().toRotationMatrix();
}

// max |R^T R - I|: how far r is from orthonormal.
double OrthonormalityError(const Eigen::Matrix3d& r) {
  return (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
}

using Fields = std::vector<std::string_view>;

// Calls fn(line, fields) for each line of the text file at path that is not blank: line counts
// from 1, fields are separated by white space (and by commas if commas_separate). what names the
// kind of file in the error if it cannot be opened.
void ForEachRecord(const std::string& path, const char* what, bool commas_separate,
                   const std::function<void(int, const Fields&)>& fn) {
  std::ifstream in = OpenText(path, what);
  std::string text;
  int line = 0;
  while (std::getline(in, text)) {
    ++line;
    if (IsBlank(text)) continue;
    if (commas_separate) std::replace(text.begin(), text.end(), ',', ' ');
    fn(line, Split(text));
  }
}

// ForEachRecord, collecting what parse makes of each line.
template <class T>
std::vector<T> ReadRecords(const std::string& path, const char* what, bool commas_separate,
                           const std::function<T(int, const Fields&)>& parse) {
  std::vector<T> out;
  ForEachRecord(path, what, commas_separate,
                [&](int line, const Fields& tok) { out.push_back(parse(line, tok)); });
  return out;
}

// Refuses a line without exactly n fields: "expected n <what>, got m".
void CheckFieldCount(const Fields& tok, std::size_t n, const char* what, const std::string& path,
                     int line) {
  if (tok.size() != n) {
    Fail(path, line, "expected " + std::to_string(n) + " " + what + ", got " +
                         std::to_string(tok.size()));
  }
}

// The box of a Label or DetectionRow, from field `first` on: h w l, the bottom centre x y z
// (rect frame) and the rotation about y (named rotation_field in errors).
template <class Row>
void ParseBox(const Fields& tok, std::size_t first, const char* rotation_field,
              const std::string& path, int line, Row* row) {
  row->height = ParseDouble(tok[first], path, line, "h");
  row->width = ParseDouble(tok[first + 1], path, line, "w");
  row->length = ParseDouble(tok[first + 2], path, line, "l");
  for (std::size_t k = 0; k < 3; ++k) {
    row->bottom_center_rect[static_cast<Eigen::Index>(k)] =
        ParseDouble(tok[first + 3 + k], path, line, "location");
  }
  row->rotation_y = ParseDouble(tok[first + 6], path, line, rotation_field);
}

void CheckDimensions(double height, double width, double length, const std::string& path,
                     int line) {
  if (!(height > 0.0 && width > 0.0 && length > 0.0)) {
    std::ostringstream os;
    os << "non-positive dimensions h w l = " << height << " " << width << " " << length;
    Fail(path, line, os.str());
  }
}

}  // namespace

VelodyneFrame ReadVelodyneBin(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw KittiError("Velodyne file " + path + " is a directory, not a frame's returns");
  }
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw KittiError("cannot open Velodyne file " + path + ": " + std::strerror(errno));
  const std::streamoff bytes = in.tellg();
  if (bytes < 0) throw KittiError("cannot read the size of Velodyne file " + path);
  if (bytes % 16 != 0) {
    throw KittiError("Velodyne file " + path + " has " + std::to_string(bytes) +
                     " bytes, not a multiple of 16 (float32 x y z reflectance per return)");
  }
  const std::size_t n = static_cast<std::size_t>(bytes / 16);
  std::vector<float> raw(4 * n);
  in.seekg(0);
  if (n > 0 && !in.read(reinterpret_cast<char*>(raw.data()), bytes)) {
    throw KittiError("cannot read Velodyne file " + path + " (" + std::to_string(bytes) + " bytes)");
  }
  static_assert(sizeof(float) == 4, "KITTI .bin files hold IEEE float32");
  // KITTI files are little endian, as is every machine vtrack targets (x86-64, aarch64).
  static_assert(std::endian::native == std::endian::little, "big-endian hosts would need a byte swap");
  VelodyneFrame f;
  f.x.resize(n);
  f.y.resize(n);
  f.z.resize(n);
  f.reflectance.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    f.x[i] = raw[4 * i];
    f.y[i] = raw[4 * i + 1];
    f.z[i] = raw[4 * i + 2];
    f.reflectance[i] = raw[4 * i + 3];
  }
  return f;
}

Eigen::Affine3d Calibration::RectFromVelo() const {
  Eigen::Affine3d rect_from_cam = Eigen::Affine3d::Identity();
  rect_from_cam.linear() = R0_rect;
  return rect_from_cam * cam_from_velo;
}

Eigen::Affine3d Calibration::VeloFromRect() const { return RectFromVelo().inverse(Eigen::Affine); }

Calibration ReadCalibration(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw KittiError("calibration file " + path + " is a directory (calib/NNNN.txt is the file)");
  }
  // Canonical key -> (number of values, line found, values).
  struct Entry {
    int line = 0;
    std::vector<double> values;
  };
  std::map<std::string, Entry> entries;
  const std::map<std::string, std::string> aliases = {
      {"P0", "P0"}, {"P1", "P1"}, {"P2", "P2"}, {"P3", "P3"},
      {"R0_rect", "R0_rect"}, {"R_rect", "R0_rect"},
      {"Tr_velo_to_cam", "Tr_velo_to_cam"}, {"Tr_velo_cam", "Tr_velo_to_cam"},
      {"Tr_imu_to_velo", "Tr_imu_to_velo"}, {"Tr_imu_velo", "Tr_imu_to_velo"}};
  const std::map<std::string, std::size_t> sizes = {
      {"P0", 12}, {"P1", 12}, {"P2", 12}, {"P3", 12},
      {"R0_rect", 9}, {"Tr_velo_to_cam", 12}, {"Tr_imu_to_velo", 12}};
  auto read_entry = [&](int line, const Fields& tok) {
    std::string key(tok[0]);
    if (!key.empty() && key.back() == ':') key.pop_back();
    const auto alias = aliases.find(key);
    if (alias == aliases.end()) return;  // other calibration entries (e.g. Tr_cam_to_road) are not needed
    const std::string& canon = alias->second;
    const std::size_t want = sizes.at(canon);
    if (tok.size() - 1 != want) {
      Fail(path, line, key + " has " + std::to_string(tok.size() - 1) + " values, expected " +
                           std::to_string(want));
    }
    if (entries.count(canon)) Fail(path, line, "duplicate entry " + key);
    Entry e;
    e.line = line;
    for (std::size_t k = 1; k < tok.size(); ++k) {
      e.values.push_back(ParseDouble(tok[k], path, line, key.c_str()));
    }
    entries[canon] = std::move(e);
  };
  ForEachRecord(path, "calibration", /*commas_separate=*/false, read_entry);
  for (const char* required : {"P2", "R0_rect", "Tr_velo_to_cam"}) {
    if (!entries.count(required)) {
      Fail(path, 0, std::string("missing calibration entry ") + required);
    }
  }
  auto mat34 = [](const std::vector<double>& v) {
    Eigen::Matrix<double, 3, 4> m;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) m(r, c) = v[static_cast<std::size_t>(4 * r + c)];
    }
    return m;
  };
  auto rigid = [&](const std::string& key) {
    const Entry& e = entries.at(key);
    const Eigen::Matrix<double, 3, 4> m = mat34(e.values);
    const Eigen::Matrix3d r = m.leftCols<3>();
    if (OrthonormalityError(r) > 1e-3 || r.determinant() < 0.0) {
      std::ostringstream os;
      os << key << " is not a rigid transform: its 3x3 block is not a rotation (det "
         << r.determinant() << ")";
      Fail(path, e.line, os.str());
    }
    Eigen::Affine3d t = Eigen::Affine3d::Identity();
    t.matrix().topRows<3>() = m;
    return t;
  };
  Calibration c;
  static const char* kProjections[4] = {"P0", "P1", "P2", "P3"};
  for (std::size_t k = 0; k < 4; ++k) {
    if (entries.count(kProjections[k])) c.P[k] = mat34(entries.at(kProjections[k]).values);
  }
  const Entry& r0 = entries.at("R0_rect");
  for (int r = 0; r < 3; ++r) {
    for (int col = 0; col < 3; ++col) c.R0_rect(r, col) = r0.values[static_cast<std::size_t>(3 * r + col)];
  }
  if (OrthonormalityError(c.R0_rect) > 1e-3 || c.R0_rect.determinant() < 0.0) {
    Fail(path, r0.line, "R0_rect is not a rotation");
  }
  c.cam_from_velo = rigid("Tr_velo_to_cam");
  if (entries.count("Tr_imu_to_velo")) c.velo_from_imu = rigid("Tr_imu_to_velo");
  return c;
}

std::int8_t ClassOfType(const std::string& type) {
  using O = vtrack::object_t;
  if (type == "Car") return O::CLASS_CAR;
  if (type == "Van") return O::CLASS_VAN;
  if (type == "Truck") return O::CLASS_TRUCK;
  if (type == "Cyclist") return O::CLASS_CYCLIST;
  if (type == "Pedestrian" || type == "Person_sitting" || type == "Person") return O::CLASS_PEDESTRIAN;
  if (type == "Tram" || type == "Misc") return O::CLASS_OTHER;
  if (type == "DontCare") return O::CLASS_UNKNOWN;
  throw KittiError("unknown KITTI object type '" + type + "'");
}

std::vector<Label> ReadLabels(const std::string& path) {
  auto parse = [&](int line, const Fields& tok) {
    if (tok.size() != 17 && tok.size() != 18) {
      Fail(path, line, "expected 17 fields (frame track_id type truncated occluded alpha x1 y1 x2 y2 "
                       "h w l x y z rotation_y) or 18 (with score), got " + std::to_string(tok.size()));
    }
    Label l;
    l.line = line;
    l.frame = ParseInt(tok[0], path, line, "frame");
    l.track_id = ParseInt(tok[1], path, line, "track_id");
    l.type = std::string(tok[2]);
    try {
      ClassOfType(l.type);
    } catch (const KittiError& e) {
      Fail(path, line, e.what());
    }
    l.truncated = ParseDouble(tok[3], path, line, "truncated");
    l.occluded = ParseIntegral(tok[4], path, line, "occluded");
    l.alpha = ParseDouble(tok[5], path, line, "alpha");
    for (int k = 0; k < 4; ++k) l.bbox[k] = ParseDouble(tok[6 + static_cast<std::size_t>(k)], path, line, "bbox");
    ParseBox(tok, 10, "rotation_y", path, line, &l);
    if (l.frame < 0) Fail(path, line, "negative frame " + std::to_string(l.frame));
    if (l.IsDontCare()) {
      if (l.track_id != -1) Fail(path, line, "DontCare with track_id " + std::to_string(l.track_id) + " (expected -1)");
    } else {
      if (l.track_id < 0) Fail(path, line, "negative track_id " + std::to_string(l.track_id) + " for " + l.type);
      CheckDimensions(l.height, l.width, l.length, path, line);
    }
    return l;
  };
  return ReadRecords<Label>(path, "label", /*commas_separate=*/false, parse);
}

std::vector<DetectionRow> ReadDetections(const std::string& path) {
  auto parse = [&](int line, const Fields& tok) {
    CheckFieldCount(tok, 15, "comma-separated fields (frame,type,x1,y1,x2,y2,score,h,w,l,x,y,z,"
                             "rot_y,alpha)", path, line);
    DetectionRow d;
    d.line = line;
    d.frame = ParseInt(tok[0], path, line, "frame");
    d.type = ParseInt(tok[1], path, line, "type");
    d.score = ParseDouble(tok[6], path, line, "score");
    ParseBox(tok, 7, "rot_y", path, line, &d);
    if (d.frame < 0) Fail(path, line, "negative frame " + std::to_string(d.frame));
    CheckDimensions(d.height, d.width, d.length, path, line);
    return d;
  };
  return ReadRecords<DetectionRow>(path, "detections", /*commas_separate=*/true, parse);
}

std::vector<Eigen::Isometry3d> ReadPoses(const std::string& path) {
  auto parse = [&](int line, const Fields& tok) {
    CheckFieldCount(tok, 12, "values (row-major 3x4 [R|t])", path, line);
    Eigen::Matrix<double, 3, 4> m;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) m(r, c) = ParseDouble(tok[static_cast<std::size_t>(4 * r + c)], path, line, "pose");
    }
    const Eigen::Matrix3d r = m.leftCols<3>();
    const double err = OrthonormalityError(r);
    if (err > 1e-3 || r.determinant() < 0.0) {
      std::ostringstream os;
      os << "rotation block is not a rotation (max |R^T R - I| = " << err << ", det "
         << r.determinant() << ")";
      Fail(path, line, os.str());
    }
    Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
    p.linear() = Orthonormalised(r);
    p.translation() = m.col(3);
    return p;
  };
  std::vector<Eigen::Isometry3d> poses =
      ReadRecords<Eigen::Isometry3d>(path, "poses", /*commas_separate=*/false, parse);
  if (poses.empty()) Fail(path, 0, "no poses in the file");
  return poses;
}

std::vector<OxtsRecord> ReadOxts(const std::string& path) {
  auto parse = [&](int line, const Fields& tok) {
    CheckFieldCount(tok, 30, "OXTS values (lat lon alt roll pitch yaw vn ve vf vl vu ax ay az af al "
                             "au wx wy wz wf wl wu pos_accuracy vel_accuracy navstat numsats posmode "
                             "velmode orimode)", path, line);
    static const char* kNames[25] = {"lat", "lon", "alt", "roll", "pitch", "yaw", "vn", "ve", "vf",
                                     "vl", "vu", "ax", "ay", "az", "af", "al", "au", "wx", "wy",
                                     "wz", "wf", "wl", "wu", "pos_accuracy", "vel_accuracy"};
    double v[25];
    for (std::size_t k = 0; k < 25; ++k) v[k] = ParseDouble(tok[k], path, line, kNames[k]);
    OxtsRecord r;
    r.lat = v[0]; r.lon = v[1]; r.alt = v[2];
    r.roll = v[3]; r.pitch = v[4]; r.yaw = v[5];
    r.vn = v[6]; r.ve = v[7]; r.vf = v[8]; r.vl = v[9]; r.vu = v[10];
    r.ax = v[11]; r.ay = v[12]; r.az = v[13]; r.af = v[14]; r.al = v[15]; r.au = v[16];
    r.wx = v[17]; r.wy = v[18]; r.wz = v[19]; r.wf = v[20]; r.wl = v[21]; r.wu = v[22];
    r.pos_accuracy = v[23]; r.vel_accuracy = v[24];
    r.navstat = ParseIntegral(tok[25], path, line, "navstat");
    r.numsats = ParseIntegral(tok[26], path, line, "numsats");
    r.posmode = ParseIntegral(tok[27], path, line, "posmode");
    r.velmode = ParseIntegral(tok[28], path, line, "velmode");
    r.orimode = ParseIntegral(tok[29], path, line, "orimode");
    if (std::abs(r.lat) >= 90.0) {
      Fail(path, line, "latitude " + std::string(tok[0]) + " deg is outside (-90, 90)");
    }
    if (std::abs(r.lon) > 180.0) {
      Fail(path, line, "longitude " + std::string(tok[1]) + " deg is outside [-180, 180]");
    }
    return r;
  };
  std::vector<OxtsRecord> out =
      ReadRecords<OxtsRecord>(path, "OXTS", /*commas_separate=*/false, parse);
  if (out.empty()) Fail(path, 0, "no OXTS records in the file");
  return out;
}

std::vector<Eigen::Isometry3d> OxtsToImuPoses(const std::vector<OxtsRecord>& records) {
  constexpr double kEarthRadius = 6378137.0;  // [m] WGS84 equatorial radius, as in the KITTI devkit
  std::vector<Eigen::Isometry3d> poses;
  if (records.empty()) return poses;
  const double scale = std::cos(records.front().lat * kPi / 180.0);
  Eigen::Isometry3d first_inv = Eigen::Isometry3d::Identity();
  for (std::size_t i = 0; i < records.size(); ++i) {
    const OxtsRecord& r = records[i];
    // Mercator projection at the first record's scale.
    const double mx = scale * r.lon * kPi * kEarthRadius / 180.0;
    const double my = scale * kEarthRadius * std::log(std::tan((90.0 + r.lat) * kPi / 360.0));
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.translation() = Eigen::Vector3d(mx, my, r.alt);
    t.linear() = (Eigen::AngleAxisd(r.yaw, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(r.pitch, Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(r.roll, Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    if (i == 0) first_inv = t.inverse();
    poses.push_back(first_inv * t);
  }
  return poses;
}

std::vector<Eigen::Isometry3d> ImuPosesToVeloPoses(const std::vector<Eigen::Isometry3d>& imu0_from_imu,
                                                   const Eigen::Affine3d& velo_from_imu) {
  // Re-orthonormalise the calibration's rotation so that the results are exact rigid motions.
  Eigen::Isometry3d velo_from_imu_rigid = Eigen::Isometry3d::Identity();
  velo_from_imu_rigid.linear() = Orthonormalised(velo_from_imu.linear());
  velo_from_imu_rigid.translation() = velo_from_imu.translation();
  const Eigen::Isometry3d imu_from_velo = velo_from_imu_rigid.inverse();
  std::vector<Eigen::Isometry3d> out;
  out.reserve(imu0_from_imu.size());
  for (const auto& p : imu0_from_imu) out.push_back(velo_from_imu_rigid * p * imu_from_velo);
  return out;
}

}  // namespace vtrack::kitti
