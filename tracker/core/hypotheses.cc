#include "tracker/core/hypotheses.h"

#include <cmath>

#include "base/angle.h"
#include "tracker/core/orientation.h"

namespace vtrack {

Hypothesis PredictReported(const Ekf& ekf, const Track& t, std::int64_t utime) {
  const TrackHypothesis& h = t.hyps[static_cast<std::size_t>(t.selected)];
  Hypothesis out = h.filter;
  const double dt = static_cast<double>(utime - t.state_utime) * 1e-6;
  if (dt > 0.0) {
    ekf.Predict(dt, h.noise_scale, &out);
  } else if (dt < 0.0) {
    const MotionModel& m = ekf.model(out.kind);
    Matrix6d Phi;
    const Vector6d x = m.Propagate(out.x, dt, &Phi);
    out.P = Phi * out.P * Phi.transpose() + h.noise_scale * m.ProcessNoise(out.x, -dt);
    out.P = 0.5 * (out.P + out.P.transpose()).eval();
    out.x = x;
  }
  return out;
}

void AddScoreTerm(double term, int window, TrackHypothesis* h) {
  h->score_terms.push_back(term);
  while (static_cast<int>(h->score_terms.size()) > window) h->score_terms.pop_front();
}

void SelectHypothesis(double switch_margin, Track* t) {
  int best = t->selected;
  double best_score = t->hyps[static_cast<std::size_t>(best)].Score();
  for (std::size_t k = 0; k < t->hyps.size(); ++k) {
    const double s = t->hyps[k].Score();
    if (s < best_score - switch_margin || !std::isfinite(best_score)) {
      best = static_cast<int>(k);
      best_score = s;
    }
  }
  t->selected = best;
}

void ReseedFailedHypotheses(const Ekf& ekf, int fail_misses, Track* t) {
  const TrackHypothesis& sel = t->hyps[static_cast<std::size_t>(t->selected)];
  if (!sel.updated_this_scan) return;
  for (std::size_t k = 0; k < t->hyps.size(); ++k) {
    if (static_cast<int>(k) == t->selected) continue;
    TrackHypothesis& h = t->hyps[k];
    if (h.consecutive_misses < fail_misses) continue;
    h.filter = ekf.Convert(sel.filter, h.filter.kind, 0.0);
    h.shape = sel.shape;
    h.RefreshShape();
    h.length_seen_full = sel.length_seen_full;
    h.width_seen_full = sel.width_seen_full;
    h.score_terms = sel.score_terms;
    h.last_logdet = sel.last_logdet;
    h.consecutive_misses = 0;
  }
}

void SpawnVasms(const Ekf& ekf, const TrackManagerParams& params, Track* t) {
  const TrackHypothesis base = t->hyps[0];
  const CentreEstimate c = ekf.Centre(base.filter);
  const double theta = PoseOf(ekf.model(base.filter.kind), base.filter.x)(2);
  const double off = AngleDiff(c.velocity_heading, theta);
  const int k_main = static_cast<int>(std::lround(off / (0.5 * kPi)));
  const double resid = AngleDiff(c.velocity_heading, theta + k_main * 0.5 * kPi);  // [-45, 45] deg
  const bool ambiguous = std::abs(resid) > DegToRad(45.0 - params.ambiguity_deg);
  const int k_alt = k_main + (resid > 0 ? 1 : -1);
  const int num_vasm = params.max_hypotheses - 1;
  for (int s = 0; s < num_vasm; ++s) {
    HypothesisVariant v = params.vasm_variants[static_cast<std::size_t>(s)];
    int k = k_main;
    if (ambiguous && s == 1) {
      v = params.vasm_variants[0];
      k = k_alt;
    }
    TrackHypothesis h = base;
    TurnAxis(ekf, ModelKind::kVasm, k, &h);
    h.inside_fraction = v.inside_fraction;
    h.noise_scale = v.noise_scale;
    h.consecutive_misses = 0;
    h.has_fit = false;
    t->hyps.push_back(std::move(h));
  }
}

}  // namespace vtrack
