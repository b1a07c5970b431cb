// A one-item mailbox between a producer that must never wait (the LCM thread) and a consumer
// that may be slow (the render thread): Put replaces an item not yet taken and counts it as
// dropped, so the consumer always gets the newest.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <utility>

namespace vtrack::viewer {

template <class T>
class LatestSlot {
 public:
  // Never blocks beyond a short lock. Returns true if an item that was not taken was replaced.
  bool Put(T item) {
    bool replaced = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (closed_) return false;
      replaced = item_.has_value();
      if (replaced) ++dropped_;
      item_ = std::move(item);
    }
    cv_.notify_one();
    return replaced;
  }

  // Waits for an item; nullopt once closed and empty.
  std::optional<T> Take() {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [&] { return item_.has_value() || closed_; });
    std::optional<T> out = std::move(item_);
    item_.reset();
    return out;
  }

  // After Close, Put does nothing and Take returns what is left, then nullopt.
  void Close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    cv_.notify_all();
  }

  // Items replaced before they were taken, and items removed by DropRemaining.
  std::int64_t dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
  }
  // Counts an item left in the slot as dropped and removes it (for a consumer that gave up).
  void DropRemaining() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (item_) {
      ++dropped_;
      item_.reset();
    }
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::optional<T> item_;
  bool closed_ = false;
  std::int64_t dropped_ = 0;
};

}  // namespace vtrack::viewer
