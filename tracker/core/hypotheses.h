// A track's hypotheses (paper Section 2.5; the scheme is described in track_manager.h):
// prediction of the reported one, the score, the choice of the reported hypothesis, re-seeding
// of failed hypotheses and the VASM hypotheses of a mover.
#pragma once

#include <cstdint>

#include "tracker/core/ekf.h"
#include "tracker/core/track.h"
#include "tracker/core/parameters.h"

namespace vtrack {

// The reported hypothesis of t predicted to utime: forward with the process noise Q, backward
// along the same motion with the noise of |dt| added (conservative, not subtracted).
Hypothesis PredictReported(const Ekf& ekf, const Track& t, std::int64_t utime);

// Appends one scan's score term (a negative log-likelihood) and keeps the last `window`.
void AddScoreTerm(double term, int window, TrackHypothesis* h);

// The reported hypothesis becomes the best score, but only when it beats the current one by
// switch_margin (hysteresis against flicker), or the current one has no finite score.
void SelectHypothesis(double switch_margin, Track* t);

// A hypothesis without an accepted update in fail_misses consecutive scans with points, while
// the reported one was updated, has failed: it restarts from the reported hypothesis (converted
// into its own model, same heading), keeps its own inside fraction and noise scale, and copies
// the shape and the score history.
void ReseedFailedHypotheses(const Ekf& ekf, int fail_misses, Track* t);

// Gives a mover's single hypothesis its VASM companions (slots 1 to max_hypotheses - 1): each
// takes the candidate heading nearest the velocity heading; while that heading is ambiguous
// (within ambiguity_deg of the diagonal) slot 2 takes the other candidate.
void SpawnVasms(const Ekf& ekf, const TrackManagerParams& params, Track* t);

}  // namespace vtrack
