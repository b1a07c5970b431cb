// A track's life cycle (track_manager.h, "Life cycle"): tentative -> confirmed after
// confirm_updates updates, deleted after tentative_max_misses misses while tentative; a
// confirmed track is coasting on a scan that neither updated it nor gave it returns (one given
// returns that updated none of its hypotheses stays confirmed); deleted coast_max_s after its last accepted update
// (parked_coast_max_s for a parked object) or once its position is less certain than max_position_std; of two
// overlapping tracks one goes (MarkDuplicates).
#pragma once

#include <cstdint>
#include <vector>

#include "tracker/core/association.h"
#include "tracker/core/ekf.h"
#include "tracker/core/track.h"
#include "tracker/core/parameters.h"

namespace vtrack {

// Confirmed or coasting, not a mover, and slower than mover_min_speed.
bool Parked(const Ekf& ekf, double mover_min_speed, const Track& t);

// Advances t's status after a scan at utime; predicted: its reported hypothesis at utime. False
// if the track is to be deleted.
bool AdvanceStatus(const Ekf& ekf, const TrackManagerParams& params, std::int64_t utime,
                   const Hypothesis& predicted, Track* t);

// Marks in *remove one of every two tracks whose rectangles (boxes, same order as tracks)
// overlap by more than duplicate_overlap of the smaller one: a small object inside a vehicle's
// rectangle, else (both confirmed or coasting, with vehicle evidence) the one with less of it,
// else the one with fewer updates, else the younger (a tentative track's evidence is one or two
// scans' worth). A track started on a tall thin object beside a car, older than the
// car's own track, would otherwise take the car's place and its class.
void MarkDuplicates(const TrackManagerParams& params, const std::vector<Track>& tracks,
                    const std::vector<PredictedObject>& boxes, std::vector<char>* remove);

// Fraction of a 5 x 3 lattice over the smaller rectangle that lies inside the other.
double Overlap(const OrientedBox& a, const OrientedBox& b);

}  // namespace vtrack
