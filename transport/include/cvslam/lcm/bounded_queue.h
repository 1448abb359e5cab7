#pragma once
// A fixed-capacity, thread-safe FIFO between the LCM receive thread (producer) and a
// consumer. When full, push fails and the *new* item is dropped (the caller counts it):
// the receive thread must never block, or LCM's own queues overflow instead (docs/architecture.md).

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>
#include <utility>

namespace cvslam::transport {

template <typename T>
class BoundedQueue {
 public:
  explicit BoundedQueue(std::size_t capacity) : capacity_(capacity > 0 ? capacity : 1) {}

  /// Appends `item` unless the queue is full; returns whether it was stored.
  bool tryPush(T&& item) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (items_.size() >= capacity_) return false;
      items_.push_back(std::move(item));
    }
    not_empty_.notify_one();
    return true;
  }

  /// The oldest item, if any, without waiting.
  std::optional<T> tryPop() {
    std::lock_guard<std::mutex> lock(mutex_);
    return popLocked();
  }

  /// The oldest item, waiting up to `timeout` for one to arrive.
  template <typename Rep, typename Period>
  std::optional<T> pop(std::chrono::duration<Rep, Period> timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait_for(lock, timeout, [this] { return !items_.empty(); });
    return popLocked();
  }

  std::size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.size();
  }
  std::size_t capacity() const { return capacity_; }

 private:
  std::optional<T> popLocked() {
    if (items_.empty()) return std::nullopt;
    std::optional<T> item(std::move(items_.front()));
    items_.pop_front();
    return item;
  }

  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable not_empty_;
  std::deque<T> items_;
};

}  // namespace cvslam::transport
