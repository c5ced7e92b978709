// A kinetic tournament: the highest of 500 balls thrown in the air, with flight-plan updates.
//
// Ball i's height is h(t) = h0 + v (t - t0) - 4.905 (t - t0)^2 (a parabola, degree 2). A max
// tournament keeps the highest ball as its winner, with one certificate per match. Every half
// second the 20 lowest balls are kicked up again: each gets a new flight plan from its current
// height, which the tournament takes in as a local change (update). Every 0.1 s we compare the
// winner with a brute-force maximum. Exit status 0 iff they always agree.
#include <algorithm>
#include <cstdio>
#include <optional>
#include <random>
#include <vector>

#include <kinetic/kinetic.hpp>

int main() {
  using kinetic::MotionPolynomial;
  using kinetic::ObjectId;

  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> height(0.0, 5.0), kick(5.0, 25.0);
  const auto throw_up = [&](double from_height, double now) {
    return MotionPolynomial::from({from_height, kick(rng), -4.905}, now);
  };

  // 1-D objects; the tournament finds the maximum along axis 0.
  kinetic::Session<kinetic::KineticTournament> session(/*dimension=*/1, /*options=*/{},
                                                       /*axis=*/0, kinetic::Extreme::Max);
  const int n = 500;
  for (ObjectId id = 0; id < n; ++id) session.insert(id, {throw_up(height(rng), 0.0)});

  int checks = 0, agree = 0, changes_of_leader = 0;
  std::optional<ObjectId> leader;
  for (int tick = 1; tick <= 100; ++tick) {  // t = 0.1, 0.2, ..., 10
    session.advance(0.1 * tick);
    const std::optional<ObjectId> top = session.top();

    // Brute force: the highest ball now (any ball of that height is a right answer).
    double best = -1e300;
    for (const ObjectId id : session.ids()) best = std::max(best, session.position(id)[0]);
    ++checks;
    if (top && session.position(*top)[0] == best) ++agree;
    if (top != leader) ++changes_of_leader;
    leader = top;

    if (tick % 5 == 0) {
      // A flight-plan update: the 20 lowest balls are kicked up from where they are now.
      std::vector<ObjectId> ids = session.ids();
      std::sort(ids.begin(), ids.end(), [&](ObjectId a, ObjectId b) {
        return session.position(a)[0] < session.position(b)[0];
      });
      for (int k = 0; k < 20; ++k) {
        session.update(ids[k], {throw_up(session.position(ids[k])[0], session.now())});
      }
    }
  }
  std::printf(
      "tournament over %d balls to t = %g: %llu events, the leader changed %d times, "
      "%d of %d checks agree with brute force\n",
      n, session.now(), static_cast<unsigned long long>(session.simulator().counters().events()),
      changes_of_leader, agree, checks);
  const bool ok = agree == checks && session.validate();
  std::printf("%s\n", ok ? "every maximum matches brute force" : "MISMATCH");
  return ok ? 0 : 1;
}
