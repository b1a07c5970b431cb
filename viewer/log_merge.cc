#include "viewer/log_merge.h"

namespace vtrack::viewer {

MergedLogReader::MergedLogReader(const std::vector<std::string>& paths) {
  for (const auto& p : paths) {
    readers_.push_back(std::make_unique<lcm_util::LogReader>(p));
    heads_.push_back(readers_.back()->Next());
  }
}

const lcm::LogEvent* MergedLogReader::Next(std::size_t* source) {
  if (consumed_ >= 0) {
    const auto i = static_cast<std::size_t>(consumed_);
    heads_[i] = readers_[i]->Next();
    consumed_ = -1;
  }
  std::ptrdiff_t best = -1;
  for (std::size_t i = 0; i < heads_.size(); ++i) {
    if (!heads_[i]) continue;
    if (best < 0 || heads_[i]->timestamp < heads_[static_cast<std::size_t>(best)]->timestamp) {
      best = static_cast<std::ptrdiff_t>(i);
    }
  }
  if (best < 0) return nullptr;
  consumed_ = best;
  if (source) *source = static_cast<std::size_t>(best);
  return heads_[static_cast<std::size_t>(best)];
}

std::int64_t MergedLogReader::BytesRead() const {
  std::int64_t n = 0;
  for (const auto& r : readers_) n += r->BytesRead();
  return n;
}

std::int64_t MergedLogReader::TotalBytes() const {
  std::int64_t n = 0;
  for (const auto& r : readers_) n += r->FileSize();
  return n;
}

std::vector<std::string> MergedLogReader::IncompleteLogs() const {
  std::vector<std::string> out;
  for (const auto& r : readers_) {
    if (r->damaged()) out.push_back(r->DamageSummary());
  }
  return out;
}

}  // namespace vtrack::viewer
