#include "tracker/config.h"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace vtrack {
namespace {

// Reads the keys of one YAML section into fields, remembering which keys it knows.
class Section {
 public:
  // root is const: operator[] on a const node looks up without inserting (a missing key gives
  // an undefined node); the member is copy-constructed (assigning to a Node would overwrite the
  // node it refers to).
  Section(const YAML::Node& root, const std::string& name, const std::string& origin)
      : node_(root[name]), name_(name), origin_(origin) {
    if (node_ && !node_.IsMap()) Fail(name_, "is not a mapping");
  }

  template <class T>
  void Get(const char* key, T* value) {
    known_.insert(key);
    if (!node_) return;
    const YAML::Node& cnode = node_;
    const YAML::Node v = cnode[key];
    if (!v) return;
    try {
      *value = v.as<T>();
    } catch (const YAML::Exception&) {
      Fail(name_ + "." + key, "= '" + Scalar(v) + "' is not a valid " + TypeName<T>());
    }
  }

  void GetGround(const char* key, PreprocessParams::Ground* g) {
    std::string s = ToString(*g);
    Get(key, &s);
    if (!ParseGround(s, g)) Fail(name_ + "." + key, "= '" + s + "': must be none, band or grid");
  }

  void GetMode(const char* key, TrackerMode* mode) {
    std::string s = ToString(*mode);
    Get(key, &s);
    if (!ParseTrackerMode(s, mode)) Fail(name_ + "." + key, "= '" + s + "': must be mht, ism or vasm");
  }

  void GetVariants(const char* key, std::vector<HypothesisVariant>* out) {
    known_.insert(key);
    const YAML::Node& cnode = node_;
    if (!node_ || !cnode[key]) return;
    const YAML::Node list = cnode[key];
    if (!list.IsSequence()) Fail(name_ + "." + key, "must be a list of {inside_fraction, noise_scale}");
    out->clear();
    for (std::size_t i = 0; i < list.size(); ++i) {
      const YAML::Node item = list[i];
      const std::string where = name_ + "." + key + "[" + std::to_string(i) + "]";
      if (!item.IsMap()) Fail(where, "must be a mapping {inside_fraction, noise_scale}");
      HypothesisVariant v;
      for (const auto& kv : item) {
        const std::string k = kv.first.as<std::string>();
        try {
          if (k == "inside_fraction") v.inside_fraction = kv.second.as<double>();
          else if (k == "noise_scale") v.noise_scale = kv.second.as<double>();
          else Fail(where + "." + k, "is not a known key (inside_fraction, noise_scale)");
        } catch (const YAML::Exception&) {
          Fail(where + "." + k, "= '" + Scalar(kv.second) + "' is not a number");
        }
      }
      out->push_back(v);
    }
  }

  // Every key of the section must be known.
  void Done() {
    if (!node_) return;
    for (const auto& kv : node_) {
      const std::string k = kv.first.as<std::string>();
      if (!known_.count(k)) Fail(name_ + "." + k, "is not a known key");
    }
  }

  [[noreturn]] void Fail(const std::string& key, const std::string& what) const {
    throw std::runtime_error(origin_ + ": " + key + " " + what);
  }

 private:
  static std::string Scalar(const YAML::Node& n) {
    if (n.IsScalar()) return n.Scalar();
    std::ostringstream os;
    os << n;
    return os.str();
  }
  template <class T>
  static const char* TypeName() {
    if constexpr (std::is_same_v<T, bool>) return "boolean";
    else if constexpr (std::is_integral_v<T>) return "integer";
    else if constexpr (std::is_floating_point_v<T>) return "number";
    else return "string";
  }

  YAML::Node node_;
  std::string name_, origin_;
  std::set<std::string> known_;
};

void Read(const YAML::Node& root, const std::string& origin, TrackerParams* p) {
  static const std::set<std::string> kSections = {
      "input", "preprocess", "segmentation", "association", "fit",
      "ism",   "vasm",       "ekf",          "shape",       "manager", "detections"};
  if (!root.IsMap() && !root.IsNull()) throw std::runtime_error(origin + ": top level is not a mapping");
  for (const auto& kv : root) {
    const std::string s = kv.first.as<std::string>();
    if (!kSections.count(s)) {
      throw std::runtime_error(origin + ": " + s +
                               " is not a known section (input, preprocess, segmentation, "
                               "association, fit, ism, vasm, ekf, shape, manager, detections)");
    }
  }
  {
    Section s(root, "input", origin);
    auto& q = p->input;
    s.Get("max_pose_wait_us", &q.max_pose_wait_us);
    s.Get("max_extrapolation_us", &q.max_extrapolation_us);
    s.Get("time_jump_reset_us", &q.time_jump_reset_us);
    s.Get("max_queued_scans", &q.max_queued_scans);
    s.Get("pose_history_us", &q.pose_history_us);
    s.Get("max_sweep_duration_us", &q.max_sweep_duration_us);
    s.Done();
  }
  {
    Section s(root, "preprocess", origin);
    auto& q = p->preprocess;
    s.Get("min_range", &q.min_range);
    s.Get("max_range", &q.max_range);
    s.GetGround("ground", &q.ground);
    s.Get("ground_min_rings", &q.ground_min_rings);
    s.Get("ground_height_body", &q.ground_height_body);
    s.Get("min_height", &q.min_height);
    s.Get("max_height", &q.max_height);
    s.Get("ground_cell", &q.ground_cell);
    s.Get("ground_tolerance", &q.ground_tolerance);
    s.Get("ground_max_slope", &q.ground_max_slope);
    s.Get("ground_max_grade", &q.ground_max_grade);
    s.Get("knot_us", &q.knot_us);
    s.Get("max_points", &q.max_points);
    s.Done();
  }
  {
    Section s(root, "segmentation", origin);
    auto& q = p->segmentation;
    s.Get("jump_abs", &q.jump_abs);
    s.Get("jump_rel", &q.jump_rel);
    s.Get("cell_size", &q.cell_size);
    s.Get("connectivity", &q.connectivity);
    s.Get("grid_radius", &q.grid_radius);
    s.Get("min_points", &q.min_points);
    s.Get("max_extent", &q.max_extent);
    s.Done();
  }
  {
    Section s(root, "association", origin);
    auto& q = p->association;
    s.Get("gate_margin", &q.gate_margin);
    s.Get("gate_sigma", &q.gate_sigma);
    s.Get("max_gate_margin", &q.max_gate_margin);
    s.Get("min_inside_fraction", &q.min_inside_fraction);
    s.Get("outside_penalty", &q.outside_penalty);
    s.Get("miss_cost", &q.miss_cost);
    s.Get("merge_fraction", &q.merge_fraction);
    s.Get("ignore_max_extent", &q.ignore_max_extent);
    s.Get("split_min_points", &q.split_min_points);
    s.Get("min_slant_deg", &q.min_slant_deg);
    s.Get("join_max_piece", &q.join_max_piece);
    s.Get("join_max_gap", &q.join_max_gap);
    s.Get("join_max_deg", &q.join_max_deg);
    s.Get("join_max_extent", &q.join_max_extent);
    s.Get("mover_max_length", &q.mover_max_length);
    s.Get("mover_column_width", &q.mover_column_width);
    s.Done();
  }
  {
    Section s(root, "fit", origin);
    auto& q = p->fit;
    s.Get("min_slant_deg", &q.min_slant_deg);
    s.Get("inlier_sigmas", &q.inlier_sigmas);
    s.Get("min_inlier_distance_m", &q.min_inlier_distance_m);
    s.Get("surface_std_m", &q.surface_std_m);
    s.Get("max_edge_iterations", &q.max_edge_iterations);
    s.Get("max_corner_iterations", &q.max_corner_iterations);
    s.Get("min_iterations", &q.min_iterations);
    s.Get("ransac_confidence", &q.ransac_confidence);
    s.Get("max_scoring_points", &q.max_scoring_points);
    s.Get("min_sample_separation_m", &q.min_sample_separation_m);
    s.Get("min_points", &q.min_points);
    s.Get("min_edge_inliers", &q.min_edge_inliers);
    s.Get("min_second_edge_fraction", &q.min_second_edge_fraction);
    s.Get("min_inlier_fraction", &q.min_inlier_fraction);
    s.Get("gauss_newton_iterations", &q.gauss_newton_iterations);
    s.Get("max_inlier_gap_m", &q.max_inlier_gap_m);
    s.Get("inside_margin_m", &q.inside_margin_m);
    s.Get("partial_view_sigmas", &q.partial_view_sigmas);
    s.Get("variance_factor_sigmas", &q.variance_factor_sigmas);
    s.Get("side_face_min_excess_m", &q.side_face_min_excess_m);
    s.Get("side_face_min_incidence_deg", &q.side_face_min_incidence_deg);
    s.Done();
  }
  {
    Section s(root, "ism", origin);
    auto& q = p->ism;
    s.Get("alpha", &q.alpha);
    s.Get("beta", &q.beta);
    s.Get("initial_velocity_std", &q.initial_velocity_std);
    s.Get("initial_yaw_rate_std", &q.initial_yaw_rate_std);
    s.Done();
  }
  {
    Section s(root, "vasm", origin);
    auto& q = p->vasm;
    s.Get("alpha", &q.alpha);
    s.Get("gamma", &q.gamma);
    s.Get("epsilon_L", &q.epsilon_L);
    s.Get("initial_L", &q.initial_L);
    s.Get("initial_L_std", &q.initial_L_std);
    s.Done();
  }
  {
    Section s(root, "ekf", origin);
    s.Get("gate_probability", &p->ekf.gate_probability);
    s.Done();
  }
  {
    Section s(root, "shape", origin);
    auto& q = p->shape;
    s.Get("half_life", &q.half_life);
    s.Get("bin_width", &q.bin_width);
    s.Get("max_dimension", &q.max_dimension);
    s.Get("excluded_fraction", &q.excluded_fraction);
    s.Get("smoothing_std", &q.smoothing_std);
    s.Get("min_peak_fraction", &q.min_peak_fraction);
    s.Done();
  }
  {
    Section s(root, "manager", origin);
    auto& q = p->manager;
    s.GetMode("mode", &q.mode);
    s.Get("max_hypotheses", &q.max_hypotheses);
    s.Get("ism_inside_fraction", &q.ism_inside_fraction);
    s.GetVariants("vasm_variants", &q.vasm_variants);
    s.Get("mover_confidence", &q.mover_confidence);
    s.Get("mover_min_speed", &q.mover_min_speed);
    s.Get("mover_scans", &q.mover_scans);
    s.Get("ambiguity_deg", &q.ambiguity_deg);
    s.Get("axis_swap_ratio", &q.axis_swap_ratio);
    s.Get("score_window", &q.score_window);
    s.Get("switch_margin", &q.switch_margin);
    s.Get("fail_misses", &q.fail_misses);
    s.Get("confirm_updates", &q.confirm_updates);
    s.Get("tentative_max_misses", &q.tentative_max_misses);
    s.Get("coast_max_s", &q.coast_max_s);
    s.Get("parked_coast_max_s", &q.parked_coast_max_s);
    s.Get("max_position_std", &q.max_position_std);
    s.Get("duplicate_overlap", &q.duplicate_overlap);
    s.Get("range_sigma", &q.range_sigma);
    s.Get("fit_contour_deg", &q.fit_contour_deg);
    s.Get("contour_support_height", &q.contour_support_height);
    s.Get("contour_support_range", &q.contour_support_range);
    s.Get("contour_arc_span", &q.contour_arc_span);
    s.Get("outline_min_slant_deg", &q.outline_min_slant_deg);
    s.Get("outline_min_points", &q.outline_min_points);
    s.Get("outline_min_edge_inliers", &q.outline_min_edge_inliers);
    s.Get("default_length", &q.default_length);
    s.Get("default_width", &q.default_width);
    s.Get("default_dimension_std", &q.default_dimension_std);
    s.Get("small_object_extent", &q.small_object_extent);
    s.Get("small_object_position_std", &q.small_object_position_std);
    s.Get("small_object_grown_extent", &q.small_object_grown_extent);
    s.Get("vehicle_min_length", &q.vehicle_min_length);
    s.Get("vehicle_max_length", &q.vehicle_max_length);
    s.Get("vehicle_min_width", &q.vehicle_min_width);
    s.Get("vehicle_max_width", &q.vehicle_max_width);
    s.Get("prediction_horizon_s", &q.prediction_horizon_s);
    s.Get("prediction_step_s", &q.prediction_step_s);
    s.Done();
  }
  {
    Section s(root, "detections", origin);
    auto& q = p->detections;
    std::string mode = ToString(q.mode);
    s.Get("mode", &mode);
    if (!ParseInputMode(mode, &q.mode)) {
      throw std::runtime_error(origin + ": detections.mode = '" + mode + "': must be scans, boxes or fused");
    }
    s.Get("min_score", &q.min_score);
    s.Get("birth_score", &q.birth_score);
    s.Get("position_std", &q.position_std);
    s.Get("heading_std_deg", &q.heading_std_deg);
    s.Get("gate_m", &q.gate_m);
    s.Get("gate_sigma", &q.gate_sigma);
    s.Get("max_gate_m", &q.max_gate_m);
    s.Done();
  }
  std::string error;
  if (!p->Validate(&error)) throw std::runtime_error(origin + ": " + error);
}

}  // namespace

TrackerParams ParseTrackerParams(const std::string& yaml_text, const std::string& origin) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(origin + ": not valid YAML: " + e.what());
  }
  TrackerParams p;
  Read(root, origin, &p);
  return p;
}

TrackerParams LoadTrackerParams(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read tracker config '" + path + "'");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ParseTrackerParams(ss.str(), path);
}

}  // namespace vtrack
