#pragma once
// The sizes of the benches that run one structure's events, queries and changes
// (bench_segment_tree, bench_longest_side_kdtree): --n, --events, --queries and --changes,
// declared on the harness once, and the smaller ones of --quick.

#include <cstddef>
#include <cstdint>
#include <string>

#include "harness.hpp"

namespace kinetic::bench {

struct RunSizes {
  std::size_t n = 100000;         ///< objects
  std::uint64_t events = 200000;  ///< events to process
  std::size_t queries = 2000;
  std::size_t changes = 10000;  ///< inserts, removes and updates

  /// Declares the four options on the harness (`objects`: what --n counts).
  void declare(Harness& h, const std::string& objects) {
    h.option("--n", n, objects);
    h.option("--events", events, "events to process");
    h.option("--queries", queries, "queries");
    h.option("--changes", changes, "inserts, removes and updates");
  }
  /// After parse(), under --quick: n, events and queries become these, unless the command line
  /// gave them.
  void quick(const Harness& h, std::size_t quick_n, std::uint64_t quick_events,
             std::size_t quick_queries) {
    if (!h.given("--n")) n = quick_n;
    if (!h.given("--events")) events = quick_events;
    if (!h.given("--queries")) queries = quick_queries;
  }
};

}  // namespace kinetic::bench
