// Bad input and faults at the command line (the hardening issue's defects 1-5): every one is
// refused with exit 2 and one short line naming the file, or (a failure during the run) exit 1
// with the file and the reason; nothing crashes, hangs or is silently accepted.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "support/cli.hpp"

namespace {

using Outcome = kinetic::test::CliOutcome;
using kinetic::test::write_file;

const kinetic::test::CliScratch scratch{"kinetic_hardening_"};

/// Runs the program with standard output on /dev/full (every write fails: no space left).
Outcome to_full_device(const std::string& args, const std::string& tag) {
  const std::string err = scratch.path(tag + ".stderr");
  const std::string cmd =
      std::string(KINETIC_CLI_PATH) + " " + args + " >/dev/full 2>" + err + " </dev/null";
  const int raw = std::system(cmd.c_str());
  Outcome o;
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  o.err = kinetic::test::read_file(err);
  return o;
}

/// Two points that cross at t = 2.5; no end_time (the robust search reaches its own limit).
const std::string kTwo =
    R"({"format": "kinetic-scenario/1", "dimension": 1, "start_time": 0,
  "objects": [{"id": 1, "motion": [[0, 1]]}, {"id": 2, "motion": [[5, -1]]}],
  "timeline": [{"time": 10, "op": "query", "query": {"type": "sorted"}}]})";

/// kTwo with `text` in place of the first id's value.
std::string with_first_id(const std::string& text) {
  std::string s = kTwo;
  const std::string key = R"("id": 1)";
  s.replace(s.find(key), key.size(), R"("id": )" + text);
  return s;
}

/// Exit 2, nothing on standard output, one line on standard error that starts with `prefix`
/// (after "kinetic: ", unless `prefix` starts with the program's name),
/// contains `needle` and is at most `max_length` characters long.
void expect_refused(const Outcome& o, const std::string& prefix, const std::string& needle,
                    std::size_t max_length = 400) {
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_TRUE(o.out.empty()) << o.out.substr(0, 200);
  // Every message starts with the program's name.
  const std::string start = prefix.rfind("kinetic", 0) == 0 ? prefix : "kinetic: " + prefix;
  EXPECT_EQ(o.err.rfind(start, 0), 0u) << o.err.substr(0, 400);
  EXPECT_NE(o.err.find(needle), std::string::npos) << o.err.substr(0, 400);
  EXPECT_EQ(o.err.find('\n'), o.err.size() - 1) << "one line";
  EXPECT_LE(o.err.size(), max_length) << o.err.substr(0, 400);
}

// Defect 1: a value nested 10^5 deep inside an object overflowed the stack (SIGSEGV).
TEST(CliHardening, DeepNestingIsRefusedNotACrash) {
  const std::string path = scratch.path("deep.json");
  write_file(path, with_first_id(std::string(100000, '[') + std::string(100000, ']')));
  const Outcome o = scratch.run("run " + path + " --structure sort", "deep");
  expect_refused(o, path + ": $.objects[0].id", "nested deeper than 64 levels", 1000);
  // A whole document that is one deep array, too.
  write_file(path, std::string(100000, '[') + std::string(100000, ']'));
  expect_refused(scratch.run("run " + path + " --structure sort", "deep_root"), path + ": $",
                 "nested deeper than 64 levels", 1000);
}

// Defect 2: --eps 1e294 without an end_time looped forever in the scheduler; 1.7e308 was
// refused as "finer than doubles resolve".
TEST(CliHardening, AHugeEpsIsRefusedAndNoEpsLoops) {
  const std::string path = scratch.path("two.json");
  write_file(path, kTwo);
  for (const char* eps : {"1e294", "1.7e308"}) {
    SCOPED_TRACE(eps);
    expect_refused(scratch.run("run " + path + " --structure sort --eps " + eps, "huge_eps"),
                   "kinetic: --eps", "is larger than robust scheduling takes");
  }
  // The largest eps taken finishes (events up to eps late: the order may be the old one).
  const Outcome big = scratch.run("run " + path + " --structure sort --eps 9e288", "big_eps");
  EXPECT_EQ(big.status, 0) << big.err;
  EXPECT_NE(big.out.find("\"result\""), std::string::npos);
}

// Defect 3: a valid file followed by a NUL byte and garbage was accepted.
TEST(CliHardening, AnythingAfterTheDocumentIsRefused) {
  const std::string path = scratch.path("trailing.json");
  write_file(path, kTwo + std::string("\0garbage", 8));
  expect_refused(scratch.run("run " + path + " --structure sort", "nul"), path + ": $",
                 "a NUL byte at offset " + std::to_string(kTwo.size()));
  write_file(path, kTwo + " x");
  expect_refused(scratch.run("run " + path + " --structure sort", "trailing"), path + ": $",
                 "not valid JSON");
  write_file(path, kTwo + " \n\t ");  // white space is allowed
  EXPECT_EQ(scratch.run("run " + path + " --structure sort", "whitespace").status, 0);
}

// Defect 4: an unknown 1 MB key or an unterminated 1 MB string was echoed whole.
TEST(CliHardening, MessagesQuoteOnlyAnExcerpt) {
  const std::string path = scratch.path("long.json");
  const std::string body = kTwo.substr(0, kTwo.size() - 1);
  write_file(path, body + ", \"" + std::string(1000000, 'k') + "\": 1}");
  expect_refused(scratch.run("run " + path + " --structure sort", "long_key"), path + ": $",
                 "(1000000 bytes)");
  write_file(path, body + ", \"x\": \"" + std::string(1000000, 'a'));
  expect_refused(scratch.run("run " + path + " --structure sort", "unterminated"), path + ": $",
                 "missing closing quote");
  write_file(path, with_first_id("\"" + std::string(1000000, 'i') + "\""));
  expect_refused(scratch.run("run " + path + " --structure sort", "long_string"),
                 path + ": $.objects[0].id", "(1000000 bytes)");
}

// Defect 5: exit statuses and messages of output failures, decided before the run where they
// can be; an id beyond the double range named as an id.
TEST(CliHardening, OutputFailuresNameTheFileAndTheReason) {
  const std::string path = scratch.path("two.json");
  write_file(path, kTwo);
  // A path that cannot be opened: exit 2 before anything runs, for --out and --stats alike.
  expect_refused(
      scratch.run("run " + path + " --structure sort --stats /nonexistent/s.json", "stats"),
      "kinetic: cannot write stats to /nonexistent/s.json", "No such file or directory");
  expect_refused(scratch.run("run " + path + " --structure sort --out /nonexistent/a.jsonl", "out"),
                 "kinetic: cannot write answers to /nonexistent/a.jsonl",
                 "No such file or directory");
  expect_refused(
      scratch.run("run " + path + " --structure sort --out " + ::testing::TempDir(), "dir"),
      "kinetic: cannot write answers to", "Is a directory");
  expect_refused(scratch.run("generate random-linear --n 3 --out /nonexistent/x.json", "gen"),
                 "kinetic: cannot write the scenario to /nonexistent/x.json",
                 "No such file or directory");
  // A full device during the run: exit 1, with the reason.
  const Outcome full = to_full_device("run " + path + " --structure sort", "full");
  EXPECT_EQ(full.status, 1);
  EXPECT_NE(full.err.find("kinetic: cannot write answers to standard output: No space left on "
                          "device"),
            std::string::npos)
      << full.err;
  const Outcome gen_full = to_full_device("generate random-linear --n 3", "gen_full");
  EXPECT_EQ(gen_full.status, 1);
  EXPECT_NE(gen_full.err.find("No space left on device"), std::string::npos) << gen_full.err;
  // An id beyond the range of a double.
  const std::string bad_id = scratch.path("bad_id.json");
  write_file(bad_id, with_first_id("-1e400"));
  expect_refused(scratch.run("run " + bad_id + " --structure sort", "bad_id"),
                 bad_id + ": $.objects[0].id",
                 "expected an integer id (64-bit signed), got -1e400");
}

// Defect 7: messages of the command line.
TEST(CliHardening, UnknownOptionsAreNamedWithASuggestion) {
  const std::string path = scratch.path("two.json");
  write_file(path, kTwo);
  expect_refused(scratch.run("run " + path + " --strucutre sort", "misspelt"),
                 "kinetic run: unknown option --strucutre", "(did you mean --structure?)");
  expect_refused(scratch.run("run " + path + " --structure sort --stat s.json", "stat"),
                 "kinetic run: unknown option --stat", "(did you mean --stats?)");
  expect_refused(scratch.run("generate random-linear --n 3 --qeuries 2", "gen_misspelt"),
                 "kinetic generate: unknown option --qeuries", "(did you mean --queries?)");
  expect_refused(scratch.run("run " + path + " --structure sort --zzzzzzzz 1", "far"),
                 "kinetic run: unknown option --zzzzzzzz", "see kinetic run --help");
  // A value that looks like an option is a value (here a file name given to --out).
  const Outcome value = scratch.run(
      "run " + path + " --structure sort --out " + scratch.path("--odd.jsonl"), "odd_value");
  EXPECT_EQ(value.status, 0) << value.err;
}

TEST(CliHardening, MessagesListTheChoicesAndPointToTheDefault) {
  const std::string path = scratch.path("two.json");
  write_file(path, kTwo);
  expect_refused(scratch.run("generate random-linear --n 3 --query-type nearst", "query_type"),
                 "kinetic: unknown --query-type 'nearst'", "(one of: sorted, max, min");
  expect_refused(scratch.run("run " + path + " --structure sort --scheduler exakt", "exakt"),
                 "kinetic: --scheduler must be robust, classic or exact; got 'exakt'", "");
  expect_refused(scratch.run("run " + path + " --structure sort --scheduler classic --eps 1e-6",
                             "classic_eps"),
                 "kinetic: --eps is the robust scheduler's precision",
                 "--scheduler classic does not use it");
  expect_refused(
      scratch.run("run " + scratch.path("missing.json") + " --structure sort", "missing"),
      scratch.path("missing.json") + ": cannot read", "No such file or directory");
  expect_refused(
      scratch.run("run " + path + " --structure sort --out " + scratch.path("no/dir/a.jsonl"),
                  "no_dir"),
      "kinetic: cannot write answers to " + scratch.path("no/dir/a.jsonl"),
      ": No such file or directory");
}

// Defect 8: the progress bar and an interrupted run.
TEST(CliHardening, TheProgressBarShowsARateAndIsNotRedrawnPerSlice) {
  const std::string path = scratch.path("two.json");
  write_file(path, kTwo);
  const Outcome o = scratch.run("run " + path + " --structure sort --progress", "progress");
  ASSERT_EQ(o.status, 0) << o.err;
  // A run of a few milliseconds: the first draw and the final one (at most five a second).
  EXPECT_LE(std::count(o.err.begin(), o.err.end(), '\r'), 2) << o.err;
  EXPECT_NE(o.err.find("events/s"), std::string::npos) << o.err;
  EXPECT_EQ(o.err.find("100%"), o.err.rfind("100%")) << "100% shown once: " << o.err;
}

TEST(CliHardening, AnInterruptedRunKeepsItsAnswersAndWritesItsStats) {
  // A kd-tree over 20,000 points in the plane for 10 units of time processes about 10^7 events
  // (minutes under the sanitizers); its first range queries come after a few thousand. SIGINT a
  // few seconds in: the answers given so far must be in the file (flushed), whole lines, and the
  // stats written.
  const std::string scenario = scratch.path("long.json");
  const Outcome gen = scratch.run(
      "generate random-linear --n 20000 --dimension 2 --seed 3 --queries "
      "10000 --query-type range --out " +
          scenario,
      "long_gen");
  ASSERT_EQ(gen.status, 0) << gen.err;
  const std::string answers = scratch.path("long_answers.jsonl");
  const std::string stats = scratch.path("long_stats.json");
  const std::string err = scratch.path("long.stderr");
  std::remove(answers.c_str());
  std::remove(err.c_str());
  const std::string script =
      std::string(KINETIC_CLI_PATH) + " run " + scenario + " --structure kdtree --progress --out " +
      answers + " --stats " + stats + " 2>" + err + " </dev/null & pid=$!; " +
      // Wait (up to 120 s) until the run has started (its progress bar is drawn once the signal
      // handlers are in place), then 3 s more, in which it answers its first queries (at
      // t = 0.001, 0.002, ...; they sit in the file's buffer), then interrupt.
      "for i in $(seq 1200); do grep -q events= " + err +
      " && break; sleep 0.1; done; sleep 3; kill -INT $pid; wait $pid; exit $?";
  const int raw = std::system(("bash -c '" + script + "'").c_str());
  ASSERT_TRUE(WIFEXITED(raw));
  EXPECT_EQ(WEXITSTATUS(raw), 130);
  const std::string e = kinetic::test::read_file(err);
  EXPECT_NE(e.find("kinetic: SIGINT: interrupted at t="), std::string::npos) << e;
  const std::string a = kinetic::test::read_file(answers);
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a.back(), '\n') << "whole lines only";
  const std::string st = kinetic::test::read_file(stats);
  EXPECT_NE(st.find("\"outcome\": \"interrupted\""), std::string::npos) << st;
  EXPECT_NE(st.find("\"final_time\""), std::string::npos) << st;
}

}  // namespace
