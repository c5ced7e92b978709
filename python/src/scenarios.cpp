// The scenario format (Scenario, load_scenario), the dataset generators (generate), the runner
// (run) and the paper's experiments (experiment_sorting, experiment_tournament) in Python; the
// registry's list of structures (structures()).

#include <pybind11/operators.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "common.hpp"
#include "kinetic/experiment/sorting_experiment.hpp"
#include "kinetic/experiment/tournament_experiment.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/scenario/generators.hpp"
#include "kinetic/scenario/scenario.hpp"
#include "kinetic/scenario/scenario_json.hpp"
#include "session_binding.hpp"

namespace kinetic::python {

namespace {

using scenario::Scenario;

py::object json_loads(const std::string& text) {
  return py::module_::import("json").attr("loads")(text);
}

const run::StructureInfo& structure_named(const char* name) {
  for (const run::StructureInfo& s : run::structures()) {
    if (s.name == name) return s;
  }
  throw std::logic_error(std::string("kinetic: no structure named ") + name);
}

const char* outcome_name(AdvanceOutcome o) {
  switch (o) {
    case AdvanceOutcome::Reached:
      return "reached";
    case AdvanceOutcome::LoopGuard:
      return "loop_guard";
    case AdvanceOutcome::EventBudget:
      return "event_budget";
    case AdvanceOutcome::Interrupted:
      return "interrupted";
  }
  return "?";
}

py::array_t<double> doubles(const std::vector<double>& v) {
  py::array_t<double> out(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), out.mutable_data());
  return out;
}

/// The objects' motions as one (n, d, k) array, k the largest coefficient count (zero padded).
py::array_t<double> motions_of(const Scenario& s) {
  py::ssize_t k = 1;
  for (const auto& o : s.objects) {
    for (const auto& c : o.motion.coordinates)
      k = std::max<py::ssize_t>(k, static_cast<py::ssize_t>(c.size()));
  }
  const auto n = static_cast<py::ssize_t>(s.objects.size());
  py::array_t<double> out({n, static_cast<py::ssize_t>(s.dimension), k});
  double* p = out.mutable_data();
  std::fill(p, p + out.size(), 0.0);
  for (py::ssize_t i = 0; i < n; ++i) {
    const auto& coords = s.objects[static_cast<std::size_t>(i)].motion.coordinates;
    for (std::size_t a = 0; a < coords.size(); ++a) {
      std::copy(coords[a].begin(), coords[a].end(),
                p + (i * s.dimension + static_cast<py::ssize_t>(a)) * k);
    }
  }
  return out;
}

py::dict sorting_run_dict(const experiment::SortingRun& r) {
  py::dict d;
  d["dataset"] = r.dataset;
  d["n"] = r.n;
  d["scheduler"] = to_string(r.scheduler);
  d["eps"] = r.eps;
  d["start"] = r.start;
  d["end"] = r.end;
  d["crossings"] = r.crossings;
  d["events"] = r.events;
  d["events_in_past"] = r.events_in_past;
  d["equal_time_groups"] = r.equal_time_groups;
  d["missed"] = r.missed();
  d["outcome"] = outcome_name(r.outcome);
  d["seconds"] = r.seconds;
  d["delays_measured"] = r.delays_measured;
  d["delay_rms"] = r.delay_rms;
  d["delay_max"] = r.delay_max;
  if (r.robust() && r.eps > 0.0) {
    d["delay_rms_in_eps"] = r.delay_rms / r.eps;
    d["delay_max_in_eps"] = r.delay_max / r.eps;
    // The paper's Table 1 is for n = 900 only.
    const auto paper = r.n == 900 ? experiment::paper_table1(r.dataset, r.eps) : std::nullopt;
    d["paper_delay_rms_in_eps"] = paper ? py::cast(paper->rms) : py::none();
    d["paper_delay_max_in_eps"] = paper ? py::cast(paper->max) : py::none();
    d["theorem1_checked"] = r.theorem1_checked;
    d["theorem1_violations"] = r.theorem1_violations;
    d["theorem2_bound"] = r.theorem2_bound;
    d["theorem2_holds"] = r.theorem2_holds();
  }
  d["err_max"] = r.err_max;
  d["err_final"] = r.err_final;
  d["final_inversions"] = r.final_inversions;
  d["envelope"] = doubles(r.envelope);
  return d;
}

py::dict tournament_run_dict(const experiment::TournamentRun& r) {
  py::dict d;
  d["dataset"] = r.dataset;
  d["n"] = r.n;
  d["scheduler"] = to_string(r.scheduler);
  d["eps"] = r.eps;
  d["rounding"] = r.rounding;
  d["exact_decisions"] = r.exact_decisions;
  d["start"] = r.start;
  d["end"] = r.end;
  d["events"] = r.events;
  d["external"] = r.external;
  d["outcome"] = outcome_name(r.outcome);
  d["seconds"] = r.seconds;
  d["err_max"] = r.err_max;
  d["err_rms"] = r.err_rms;
  d["wrong_fraction"] = r.wrong_fraction;
  d["theorem7_bound"] = r.theorem7_bound;
  d["samples"] = r.samples;
  d["theorem7_violations"] = r.theorem7_violations;
  d["envelope"] = doubles(r.envelope);
  return d;
}

}  // namespace

SchedulerKind default_scheduler(const char* cli_name, int max_degree) {
  return run::default_scheduler(structure_named(cli_name), max_degree);
}

void register_scenarios(py::module_& m) {
  py::class_<Scenario> sc(m, "Scenario",
                          "A scenario: objects with their motions and a timeline of queries and "
                          "changes (the format of docs/scenario-format.md).");
  sc.def_static(
      "from_json",
      [](const std::string& text, const std::string& name) {
        return scenario::parse_scenario(text, name);
      },
      py::arg("text"), py::arg("name") = "<string>", "Parses a scenario from its JSON text.");
  sc.def_static(
      "from_dict",
      [](const py::object& document) {
        const std::string text = py::str(py::module_::import("json").attr("dumps")(document));
        return scenario::parse_scenario(text, "<dict>");
      },
      py::arg("document"), "Makes a scenario from the dict of its JSON document (to_dict()).");
  sc.def(
      "to_json", [](const Scenario& s) { return scenario::write_scenario(s); },
      "The scenario's JSON text.");
  sc.def(
      "save",
      [](const Scenario& s, const std::string& path) {
        std::ofstream out(path, std::ios::binary);
        out << scenario::write_scenario(s);
        out.close();
        if (!out) throw PreconditionError("Scenario.save: cannot write " + path);
      },
      py::arg("path"), "Writes the scenario's JSON to path.");
  sc.def(
      "to_dict", [](const Scenario& s) { return json_loads(scenario::write_scenario(s)); },
      "The scenario as the dict of its JSON document.");
  sc.def_property_readonly("dimension", [](const Scenario& s) { return s.dimension; });
  sc.def_property_readonly(
      "objects", [](const Scenario& s) { return std::string(to_string(s.objects_are)); },
      "What the objects are: points, intervals or boxes.");
  sc.def_property_readonly("start_time", [](const Scenario& s) { return s.start_time; });
  sc.def_property_readonly(
      "end_time", [](const Scenario& s) { return s.end_time; },
      "The end of the window; None: until no event is left.");
  sc.def("__len__", [](const Scenario& s) { return s.objects.size(); });
  sc.def_property_readonly("ids", [](const Scenario& s) {
    std::vector<ObjectId> ids;
    for (const auto& o : s.objects) ids.push_back(o.id);
    return id_array(ids);
  });
  sc.def_property_readonly("motions", &motions_of,
                           "The objects' motions, (n, d, k) coefficients (zero padded).");
  sc.def_property_readonly("origins", [](const Scenario& s) {
    std::vector<double> o;
    for (const auto& obj : s.objects) o.push_back(obj.motion.origin);
    return doubles(o);
  });
  sc.def_property_readonly("half_extents", [](const Scenario& s) -> py::object {
    if (s.objects_are != scenario::ObjectsAre::Boxes) return py::none();
    py::array_t<double> out(
        {static_cast<py::ssize_t>(s.objects.size()), static_cast<py::ssize_t>(s.dimension)});
    double* p = out.mutable_data();
    for (const auto& o : s.objects) p = std::copy(o.half_extents.begin(), o.half_extents.end(), p);
    return out;
  });
  sc.def_property_readonly(
      "timeline",
      [](const Scenario& s) {
        const py::object document = json_loads(scenario::write_scenario(s));
        return py::object(document["timeline"]);
      },
      "The timeline's ops as dicts (time, op, and the query or the change).");
  sc.def(py::self == py::self);  // NOLINT
  sc.def("__repr__", [](const Scenario& s) {
    return "kinetic.Scenario(n=" + std::to_string(s.objects.size()) +
           ", dimension=" + std::to_string(s.dimension) + ", objects=\"" +
           to_string(s.objects_are) + "\", timeline=" + std::to_string(s.timeline.size()) + " ops)";
  });

  m.def("load_scenario", &scenario::load_scenario, py::arg("path"),
        "Reads a scenario file (JSON).");
  m.def(
      "generate",
      [](const std::string& dataset, std::size_t n, std::uint64_t seed, int dimension, int degree,
         std::optional<double> start, std::optional<double> end, std::size_t queries,
         const std::string& query_type, std::size_t updates, std::size_t inserts,
         std::size_t removes, double scale) {
        const auto type = scenario::query_type_from_string(query_type);
        if (!type) throw PreconditionError("generate: unknown query type \"" + query_type + "\"");
        return scenario::generate(dataset, scenario::GeneratorOptions{.n = n,
                                                                      .seed = seed,
                                                                      .dimension = dimension,
                                                                      .degree = degree,
                                                                      .start_time = start,
                                                                      .end_time = end,
                                                                      .queries = queries,
                                                                      .query_type = *type,
                                                                      .updates = updates,
                                                                      .inserts = inserts,
                                                                      .removes = removes,
                                                                      .scale = scale});
      },
      py::arg("dataset"), py::kw_only(), py::arg("n") = 1000, py::arg("seed") = 1,
      py::arg("dimension") = 0, py::arg("degree") = 2, py::arg("start") = py::none(),
      py::arg("end") = py::none(), py::arg("queries") = 0, py::arg("query_type") = "sorted",
      py::arg("updates") = 0, py::arg("inserts") = 0, py::arg("removes") = 0,
      py::arg("scale") = 1.0,
      "A synthetic scenario (the datasets of `kinetic generate`; datasets() lists them); the "
      "same arguments give the same scenario bit for bit.");
  m.def("datasets", &scenario::dataset_names, "The names generate() takes.");

  m.def(
      "structures",
      []() {
        py::list out;
        for (const run::StructureInfo& s : run::structures()) {
          py::dict d;
          d["name"] = s.name;
          d["python_class"] = s.python_class;
          d["description"] = s.description;
          py::list queries;
          for (const auto q : s.queries) queries.append(to_string(q));
          d["queries"] = queries;
          d["objects"] = to_string(s.objects);
          d["min_dimension"] = s.min_dimension;
          d["max_dimension"] = s.max_dimension;
          py::list schedulers;
          for (const auto k : s.schedulers) schedulers.append(to_string(k));
          d["schedulers"] = schedulers.empty()
                                ? py::list(py::make_tuple("robust", "classic", "exact"))
                                : schedulers;
          out.append(d);
        }
        return out;
      },
      "The structures built, as `kinetic run --help` lists them.");

  m.def(
      "run",
      [](const Scenario& s, const std::string& structure, std::optional<std::string> scheduler,
         double eps, bool events, bool validate, bool measure_delays,
         std::optional<std::string> trace, std::optional<double> time_limit) {
        if (time_limit && !(*time_limit > 0.0))
          throw PreconditionError("run: time_limit must be a number of seconds > 0");
        run::RunOptions o;
        o.structure = structure;
        // No scheduler: the structure's default for this scenario (robust where it takes it).
        o.scheduler =
            scheduler ? scheduler_from(*scheduler, "run") : run::default_scheduler(s, structure);
        o.eps = eps;
        o.log_events = events;
        o.validate_every_event = validate;
        o.measure_delays = measure_delays;
        run::check_runnable(s, o, "<scenario>");
        std::atomic<bool> interrupt{false};
        o.interrupt = &interrupt;
        InterruptScope scope(interrupt);
        std::ostringstream answers, log;
        std::ofstream trace_file;
        if (trace) {
          trace_file.open(*trace, std::ios::binary);
          if (!trace_file) throw PreconditionError("run: cannot write the trace to " + *trace);
        }
        run::RunResult result;
        // A time limit: a watchdog thread raises the run's interrupt flag when it passes (a
        // flag of its own says so: not a Ctrl-C to deliver).
        std::atomic<bool> timed_out{false};
        std::mutex watch;
        std::condition_variable finished;
        bool run_done = false;
        std::thread watchdog;
        if (time_limit) {
          watchdog = std::thread([&] {
            std::unique_lock<std::mutex> hold(watch);
            if (!finished.wait_for(hold, std::chrono::duration<double>(*time_limit),
                                   [&] { return run_done; })) {
              timed_out.store(true);
              interrupt.store(true);
            }
          });
        }
        {
          py::gil_scoped_release release;
          result = run::run(s, o, answers, events ? &log : nullptr, trace ? &trace_file : nullptr);
          if (watchdog.joinable()) {
            {
              const std::lock_guard<std::mutex> hold(watch);
              run_done = true;
            }
            finished.notify_all();
            watchdog.join();
          }
        }
        if (timed_out.load() && result.outcome == run::RunOutcome::Interrupted) {
          interrupt.store(false);  // the flag was the watchdog's: nothing to deliver
          throw PreconditionError("run: the time limit of " + std::to_string(*time_limit) +
                                  " s passed at t = " + std::to_string(result.stats.final_time) +
                                  " of the scenario");
        }
        if (trace) {
          trace_file.close();
          if (!trace_file) throw PreconditionError("run: cannot write the trace to " + *trace);
        }
        // Stopped by Ctrl-C, or a signal after the run's last look at the flag: Python's
        // handler runs now (usually KeyboardInterrupt; a handler that does not raise gets the
        // result so far, outcome "interrupted" when the run stopped early).
        if ((result.outcome == run::RunOutcome::Interrupted || scope.raised()) && scope.deliver()) {
          throw py::error_already_set();
        }
        py::dict out;
        out["outcome"] = run::to_string(result.outcome);
        out["message"] = result.message;
        py::list answer_list;
        std::istringstream lines(answers.str());
        for (std::string line; std::getline(lines, line);) {
          if (!line.empty()) answer_list.append(json_loads(line));
        }
        out["answers"] = answer_list;
        out["stats"] = json_loads(run::stats_json(result, o));
        if (events) {
          py::list event_list;
          std::istringstream elines(log.str());
          for (std::string line; std::getline(elines, line);) {
            if (!line.empty()) event_list.append(json_loads(line));
          }
          out["events"] = event_list;
        }
        return out;
      },
      py::arg("scenario"), py::arg("structure"), py::kw_only(), py::arg("scheduler") = py::none(),
      py::arg("eps") = 1e-9, py::arg("events") = false, py::arg("validate") = false,
      py::arg("measure_delays") = false, py::arg("trace") = py::none(),
      py::arg("time_limit") = py::none(),
      "Runs a scenario through a structure, as `kinetic run` (scheduler None: the structure's "
      "default, robust wherever it takes the scenario): a dict with the outcome, the "
      "answers of the timeline's queries (one dict each, as the JSON lines), the stats (as "
      "--stats) and, with events=True, every external event; with trace=PATH, the run's trace "
      "(kinetic-trace/2, for `kinetic view`); with time_limit=SECONDS, PreconditionError when "
      "the run takes longer.");

  m.def(
      "experiment_sorting",
      [](std::vector<std::string> datasets, std::size_t n, std::vector<double> eps, bool classic,
         bool exact, std::uint64_t seed, std::size_t bins, unsigned workers) {
        experiment::SortingExperimentOptions o;
        o.workers = workers;
        o.datasets = std::move(datasets);
        o.n = n;
        o.eps = std::move(eps);
        o.classic = classic;
        o.exact = exact;
        o.seed = seed;
        o.bins = bins;
        experiment::SortingExperiment e;
        {
          py::gil_scoped_release release;
          e = experiment::run_sorting_experiment(o);
        }
        py::dict out;
        out["report"] = experiment::report_text(e);
        out["table1_csv"] = experiment::table1_csv(e);
        py::list runs;
        for (const auto& r : e.runs) runs.append(sorting_run_dict(r));
        out["runs"] = runs;
        return out;
      },
      py::kw_only(), py::arg("datasets") = std::vector<std::string>{"grids", "parabola", "randdc"},
      py::arg("n") = 900, py::arg("eps") = std::vector<double>{1e-6, 1e-7, 1e-8},
      py::arg("classic") = true, py::arg("exact") = true, py::arg("seed") = 1,
      py::arg("bins") = 2000, py::arg("workers") = 1,
      "The kinetic-sorting experiment of Abam, Agarwal, de Berg, Yu (Table 1, Figures 6-8), "
      "as `kinetic experiment sorting --quick`: a dict with the report text, Table 1 as CSV and "
      "one dict per run (delays in units of eps beside the paper's, theorem checks, error "
      "envelope).");

  m.def(
      "experiment_tournament",
      [](const std::string& dataset, std::size_t n, std::vector<double> eps,
         double classic_rounding, bool exact, std::uint64_t seed, std::size_t bins,
         unsigned workers) {
        experiment::TournamentExperimentOptions o;
        o.workers = workers;
        o.dataset = dataset;
        o.n = n;
        o.eps = std::move(eps);
        o.classic_rounding = classic_rounding;
        o.exact = exact;
        o.seed = seed;
        o.bins = bins;
        experiment::TournamentExperiment e;
        {
          py::gil_scoped_release release;
          e = experiment::run_tournament_experiment(o);
        }
        py::dict out;
        out["report"] = experiment::tournament_report_text(e);
        py::list runs;
        for (const auto& r : e.runs) runs.append(tournament_run_dict(r));
        out["runs"] = runs;
        return out;
      },
      py::kw_only(), py::arg("dataset") = "randcr", py::arg("n") = 10000,
      py::arg("eps") = std::vector<double>{1e-3, 1e-4, 1e-5}, py::arg("classic_rounding") = 1e-5,
      py::arg("exact") = true, py::arg("seed") = 1, py::arg("bins") = 2000, py::arg("workers") = 1,
      "The kinetic-tournament experiment (Figure 9): a dict with the report text and one dict "
      "per run (classic, classic with exact decisions, robust at each eps, exact: geometric "
      "error, Theorem 7's bound).");
}

}  // namespace kinetic::python
