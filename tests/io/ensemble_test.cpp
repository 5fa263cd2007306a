// Ensembles of records: per-record results, their mean and maximum, resumption, and ensemble
// objectives for studies and the optimiser.

#include <bit>
#include <cmath>
#include <filesystem>
#include <numbers>

#include <gtest/gtest.h>

#include "poundsim/analysis/response_spectrum.hpp"
#include "poundsim/io/ground_motion.hpp"
#include "poundsim/io/record_scaling.hpp"
#include "poundsim/io/study_database.hpp"
#include "poundsim/model/frame.hpp"
#include "../test_files.hpp"
#include "poundsim/io/study_run.hpp"
#include "../test_models.hpp"

namespace poundsim::io {
namespace {

namespace fs = std::filesystem;

const fs::path kRecords = fs::path(POUNDSIM_SOURCE_DIR) / "data" / "ground_motions";

std::string ensemble_input(const std::string& kind) {
  return testing::model_toml("[1, 1]", testing::fig2('c')) + R"([excitation]
kind = "record"
target_pga_g = 0.3
[analysis]
kind = ")" + kind + R"("
dt = 0.002
duration = 8.0
[ensemble]
records = ["RSN6_IMPVALL.I_I-ELC180.AT2", "elCentro.AT2", "RSN758_LOMAP_EMY260.AT2"]
)";
}

RunInput read(const std::string& text, std::vector<std::string> overrides = {}) {
  return read_input_string(text, "ensemble.toml", kRecords, overrides);
}

TEST(Ensemble, MeanAndMaximumOverTheRecords) {
  const fs::path dir = fs::temp_directory_path() / "poundsim_ensemble";
  fs::remove_all(dir);
  StudyRunOptions first;
  first.max_points = 1;
  const RunInput in = read(ensemble_input("ensemble"));
  EXPECT_FALSE(run_ensemble(in, dir, first).complete());
  const nlohmann::json s = to_json(run_ensemble(in, dir));
  ASSERT_TRUE(s["complete"].get<bool>());
  ASSERT_EQ(s["records"].size(), 3u);
  const auto rows = StudyDatabase(dir / "ensemble.sqlite").rows();
  ASSERT_EQ(rows.size(), 3u);
  for (const char* key : {"peak_V1_W", "ratio_to_free_2", "amp_u_1_1", "min_gap_1_1_m", "impacts"}) {
    double sum = 0, largest = -1;
    for (const auto& r : rows) {
      sum += r.metrics[key].get<double>();
      largest = std::max(largest, r.metrics[key].get<double>());
    }
    EXPECT_NEAR(s["mean"][key].get<double>(), sum / 3, 1e-14 * std::abs(sum)) << key;
    EXPECT_EQ(s["max"][key].get<double>(), largest) << key;
  }
  for (const auto& r : rows) {
    EXPECT_NEAR(r.metrics["pga_g"].get<double>(), 0.3, 1e-12);
    EXPECT_LT(r.metrics["energy_residual"].get<double>(), 1e-10);
  }
  fs::remove_all(dir);
}

// What the ranks of an MPI job send each other: a record's figures, every field to the bit, and
// the ensemble they make is the one made of the figures as computed.
TEST(Ensemble, ARecordsFiguresTravelAsBytesToTheBit) {
  const RunInput in = read(ensemble_input("ensemble"), {"analysis.duration=2.0"});
  std::vector<TimeHistoryFigures> records, computed;
  for (std::size_t r = 0; r < 3; ++r) {
    const TimeHistoryFigures f = record_figures(in, r, std::nullopt);
    computed.push_back(f);
    const TimeHistoryFigures back = time_history_figures_from_bytes(to_bytes(f));
    const PointFigures a{.response = f, .bare = std::nullopt}, b{.response = back, .bare = std::nullopt};
    const std::vector<FigureColumn> ca = a.columns(), cb = b.columns();
    ASSERT_EQ(ca.size(), cb.size());
    for (std::size_t k = 0; k < ca.size(); ++k) {
      EXPECT_EQ(ca[k].name, cb[k].name);
      EXPECT_EQ(std::bit_cast<std::uint64_t>(ca[k].value), std::bit_cast<std::uint64_t>(cb[k].value)) << ca[k].name;
      EXPECT_EQ(ca[k].count, cb[k].count);
    }
    records.push_back(back);
  }
  EXPECT_GT(records[0].max_peak_V_W, 0.0);
  const PointFigures whole{.response = ensemble_figures(computed), .bare = std::nullopt};
  const PointFigures pieced{.response = ensemble_figures(records), .bare = std::nullopt};
  EXPECT_EQ(io::to_json(whole), io::to_json(pieced));
}

TEST(Ensemble, BareBaselineOfAnEnsemblePointIsBarePounding) {
  // The bare-pounding reference keeps the point's model when the records are re-read.
  std::string text = ensemble_input("study");
  text += R"([study]
each = "ensemble"
[[study.parameter]]
key = "model.dimensionless.mu"
values = [2.0]
)";
  const RunInput study = read(text);
  const RunInput point = with_settings(study, study_points(*study.study)[0]);
  const PointFigures bare_figures = baseline_figures(point, 1);
  const nlohmann::json bare = to_json(bare_figures);
  const std::vector<Setting> bare_settings{make_setting("model.dimensionless.eta", {0.0}),
                                           make_setting("model.dimensionless.mu", {0.0}),
                                           make_setting("model.dimensionless.epsilon", {0.0})};
  const RunInput made_bare = with_settings(study, bare_settings);
  const nlohmann::json direct = to_json(point_figures(made_bare, 1, nullptr));
  EXPECT_EQ(bare["max_peak_V_W"], direct["max_peak_V_W"]);
  EXPECT_EQ(bare["peak_V2_W"], direct["peak_V2_W"]);
  const std::vector<FigureColumn> bare_columns = figure_columns_of(bare);
  const PointFigures with_figures = point_figures(point, 1, &bare_columns);
  const nlohmann::json with = to_json(with_figures);
  EXPECT_NE(with["max_peak_V_W"], bare["max_peak_V_W"]);  // the gap elements change the response
  EXPECT_NEAR(with["ratio_to_bare_1"].get<double>(), with["peak_V1_W"].get<double>() / bare["peak_V1_W"].get<double>(), 1e-15);
  // The typed figures and their columns agree: an ensemble's headline is its mean over records.
  EXPECT_EQ(with_figures.max_peak_V_W(), with["max_peak_V_W"].get<double>());
  EXPECT_EQ(with_figures.bare->max_ratio_to_bare, with["max_ratio_to_bare"].get<double>());
  // Drifts and accelerations against bare pounding's, frame by frame (the ensemble's means).
  for (const char* frame : {"1", "2"}) {
    const std::string f = frame;
    EXPECT_EQ(with["bare_peak_drift_" + f + "_m"], bare["peak_drift_" + f + "_m"]);
    EXPECT_NEAR(with["ratio_to_bare_drift_" + f].get<double>(),
                with["peak_drift_" + f + "_m"].get<double>() / bare["peak_drift_" + f + "_m"].get<double>(), 1e-15);
    EXPECT_NEAR(with["ratio_to_bare_acc_" + f].get<double>(),
                with["peak_abs_acc_" + f + "_g"].get<double>() / bare["peak_abs_acc_" + f + "_g"].get<double>(), 1e-15);
  }
  EXPECT_EQ(with["max_ratio_to_bare_drift"].get<double>(),
            std::max(with["ratio_to_bare_drift_1"].get<double>(), with["ratio_to_bare_drift_2"].get<double>()));
  EXPECT_EQ(with["max_ratio_to_bare_acc"].get<double>(),
            std::max(with["ratio_to_bare_acc_1"].get<double>(), with["ratio_to_bare_acc_2"].get<double>()));
  EXPECT_GT(with["ratio_to_bare_drift_1"].get<double>(), 0.0);
  EXPECT_NE(with["ratio_to_bare_drift_1"].get<double>(), 1.0);
}


/// The ensemble of ensemble_input without its [excitation] scale, and [ensemble.scaling] `scaling`.
std::string scaled_input(const std::string& scaling, const std::string& kind = "ensemble") {
  std::string text = ensemble_input(kind);
  text.replace(text.find("target_pga_g = 0.3\n"), std::string("target_pga_g = 0.3\n").size(), "");
  // 2 s of each record: what is checked is the scaling, not the response (and the sanitizer
  // build runs these too).
  text.replace(text.find("duration = 8.0"), std::string("duration = 8.0").size(), "duration = 2.0");
  return text + "[ensemble.scaling]\n" + scaling;
}

/// The records of `in` read unscaled.
std::vector<RecordExcitation> unscaled_records(const RunInput& in) {
  std::vector<RecordExcitation> out;
  for (const fs::path& file : in.ensemble->records) out.push_back(read_ground_motion(file, RecordOptions{}).excitation);
  return out;
}

// Each kind of scaling hits its target: the PGA, S_a at T₁ of frame 2 from a design spectrum, and
// the suite's mean against EC8 over [0.2 T₁, 2 T₁] (least squares in log; not below 90 %). The
// records run with those factors (ensemble.csv's excitation.scale, their PGA).
TEST(EnsembleScaling, EachKindHitsItsTarget) {
  const fs::path dir = testing::fresh_folder("ensemble_scaling");
  {
    const RunInput in = read(scaled_input("kind = \"pga\"\ntarget_g = 0.35\n"));
    const nlohmann::json s = to_json(run_ensemble(in, dir / "pga"));
    for (const auto& r : StudyDatabase(dir / "pga" / "ensemble.sqlite").rows()) {
      EXPECT_NEAR(r.metrics["pga_g"].get<double>(), 0.35, 1e-12);
    }
    EXPECT_EQ(s["scaling"]["kind"], "pga");
    EXPECT_TRUE(fs::exists(dir / "pga" / "spectra.csv"));
  }
  {
    const RunInput in = read(scaled_input("kind = \"sa\"\ndesign = \"ec8_type1\"\nground_type = \"B\"\nag_g = 0.2\nframe = 2\n"));
    const SuiteScaling scaling = suite_scaling(in);
    const double t1 = 2 * std::numbers::pi / fundamental_frequency(in.model.frames[1]);
    EXPECT_DOUBLE_EQ(scaling.first_period, t1);
    const double target = spectral_acceleration(
        Eurocode8Spectrum{.type = Eurocode8Type::type1, .ground = GroundType::B, .ag = 0.2 * 9.81}, t1);
    const std::vector<RecordExcitation> records = unscaled_records(in);
    const double periods[] = {t1};
    for (std::size_t r = 0; r < records.size(); ++r) {
      const double sa = response_spectrum(records[r], periods).pseudo_acceleration[0];
      EXPECT_NEAR(scaling.factors[r] * sa, target, 1e-12 * target);
    }
    run_ensemble(in, dir / "sa");
    const auto rows = StudyDatabase(dir / "sa" / "ensemble.sqlite").rows();
    for (std::size_t r = 0; r < rows.size(); ++r) {
      EXPECT_EQ(rows[r].parameters["excitation.scale"].get<double>(), scaling.factors[r]);
      EXPECT_NEAR(rows[r].metrics["pga_g"].get<double>(), scaling.factors[r] * scaling.pga_file_g[r], 1e-12);
    }
  }
  for (const auto& [match, extra] : {std::pair<std::string, std::string>{"least_squares", ""}, {"not_below", "fraction = 0.9\n"}}) {
    const RunInput in = read(scaled_input("kind = \"spectrum\"\ndesign = \"ec8_type1\"\nground_type = \"C\"\nag_g = 0.25\n"
                                          "match = \"" + match + "\"\npoints = 40\n" + extra));
    const SuiteScaling scaling = suite_scaling(in);
    const double t1 = 2 * std::numbers::pi / fundamental_frequency(in.model.frames[0]);
    ASSERT_TRUE(scaling.range);
    EXPECT_DOUBLE_EQ(scaling.range->first, 0.2 * t1);
    EXPECT_DOUBLE_EQ(scaling.range->second, 2 * t1);
    const std::vector<double> periods = log_spaced_periods(0.2 * t1, 2 * t1, 40);
    std::vector<ResponseSpectrum> spectra;
    for (const RecordExcitation& r : unscaled_records(in)) spectra.push_back(response_spectrum(r, periods));
    const std::vector<double> mean = mean_pseudo_acceleration(spectra);
    const DesignSpectrum ec8 = Eurocode8Spectrum{.type = Eurocode8Type::type1, .ground = GroundType::C, .ag = 0.25 * 9.81};
    double log_misfit = 0, least = 1e300;
    for (std::size_t i = 0; i < periods.size(); ++i) {
      const double ratio = scaling.factors[0] * mean[i] / spectral_acceleration(ec8, periods[i]);
      log_misfit += std::log(ratio);
      least = std::min(least, ratio);
    }
    if (match == "least_squares") {
      EXPECT_NEAR(log_misfit, 0.0, 1e-11);
    } else {
      EXPECT_NEAR(least, 0.9, 1e-13);
    }
    for (const double f : scaling.factors) EXPECT_EQ(f, scaling.factors[0]);  // one factor for the suite
  }
  fs::remove_all(dir);
}

// input.toml writes [ensemble.scaling] back: run again, the same factors and spectra.
TEST(EnsembleScaling, TheEchoedInputScalesAlike) {
  const fs::path dir = testing::fresh_folder("ensemble_scaling_echo");
  const RunInput in = read(scaled_input("kind = \"spectrum\"\ndesign = \"table\"\ntable = [[0.05, 0.5], [0.5, 0.9], [3.0, 0.1]]\n"
                                        "period_min = 0.1\nperiod_max = 1.0\nmatch = \"not_below\"\nfraction = 0.8\n"));
  run_ensemble(in, dir / "first");
  const RunInput again = read_input(dir / "first" / "input.toml");
  run_ensemble(again, dir / "second");
  EXPECT_EQ(suite_scaling(in).factors, suite_scaling(again).factors);
  EXPECT_EQ(testing::slurp(dir / "first" / "spectra.csv"), testing::slurp(dir / "second" / "spectra.csv"));
  fs::remove_all(dir);
}

// A study of ensembles scales each point's records for the point's own model.
TEST(EnsembleScaling, AStudyPointScalesForItsOwnModel) {
  std::string text = scaled_input("kind = \"sa\"\ntarget_g = 0.5\n", "study");
  text += "[study]\neach = \"ensemble\"\n[[study.parameter]]\nkey = \"model.dimensionless.lambda2\"\nvalues = [100.0, 400.0]\n";
  const RunInput study = read(text);
  std::vector<std::vector<double>> factors;
  for (const auto& values : study_points(*study.study)) factors.push_back(suite_scaling(with_settings(study, values)).factors);
  ASSERT_EQ(factors.size(), 2u);
  EXPECT_NE(factors[0], factors[1]);  // T₁ differs, so S_a there does
}

TEST(EnsembleScaling, BadTablesAreRefusedNamingTheKey) {
  const auto refused = [&](const std::string& scaling, const std::string& key, const std::string& rule) {
    try {
      (void)read(scaled_input(scaling));
      ADD_FAILURE() << "accepted: " << scaling;
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(key), std::string::npos) << what;
      EXPECT_NE(what.find(rule), std::string::npos) << what;
    }
  };
  refused("kind = \"pga\"\n", "ensemble.scaling", "missing key: target_g");
  refused("kind = \"pga\"\ntarget_g = 0.3\nmatch = \"not_below\"\n", "ensemble.scaling.match", "not for kind = \"pga\"");
  refused("kind = \"sa\"\ntarget_g = 0.3\ndesign = \"ec8_type1\"\nground_type = \"A\"\nag_g = 0.2\n", "ensemble.scaling",
          "give exactly one");
  refused("kind = \"spectrum\"\n", "ensemble.scaling", "missing key: design");
  refused("kind = \"spectrum\"\ndesign = \"ec8_type1\"\nground_type = \"F\"\nag_g = 0.2\n", "ensemble.scaling.ground_type",
          "is not one of");
  refused("kind = \"spectrum\"\ndesign = \"ec8_type2\"\nground_type = \"A\"\nag_g = -0.2\n", "ensemble.scaling.ag_g", "> 0");
  refused("kind = \"spectrum\"\ndesign = \"table\"\ntable = [[0.5, 1.0], [0.2, 2.0]]\n", "ensemble.scaling.table",
          "must increase");
  refused("kind = \"spectrum\"\ndesign = \"table\"\ntable = [[0.5, 1.0, 3.0], [0.9, 2.0, 1.0]]\n", "ensemble.scaling.table",
          "row 1");
  refused("kind = \"spectrum\"\ndesign = \"ec8_type1\"\nground_type = \"A\"\nag_g = 0.2\nfraction = 0.9\n",
          "ensemble.scaling.fraction", "only for match = \"not_below\"");
  refused("kind = \"spectrum\"\ndesign = \"ec8_type1\"\nground_type = \"A\"\nag_g = 0.2\nperiod_min = 0.5\n",
          "ensemble.scaling.period_min", "give both ends");
  refused("kind = \"spectrum\"\ndesign = \"ec8_type1\"\nground_type = \"A\"\nag_g = 0.2\nframe = 3\n", "ensemble.scaling.frame",
          "the model has 2 frame(s)");
  refused("kind = \"pga\"\ntarget_g = 0.3\nspeed = 2\n", "ensemble.scaling.speed", "unknown key");
  refused("kind = \"sa\"\ntarget_g = 0.3\nperiod = 1e-20\n", "ensemble.scaling.period", "must be in [0.001, 100] s");
  // [excitation]'s own scale would fight the suite's.
  std::string both = ensemble_input("ensemble") + "[ensemble.scaling]\nkind = \"pga\"\ntarget_g = 0.3\n";
  try {
    (void)read(both);
    ADD_FAILURE() << "accepted target_pga_g beside [ensemble.scaling]";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("excitation.target_pga_g: not with [ensemble.scaling]"), std::string::npos) << e.what();
  }
  // A range beyond the design spectrum's periods is found when the factors are computed.
  const RunInput far = read(scaled_input("kind = \"spectrum\"\ndesign = \"ec8_type1\"\nground_type = \"A\"\nag_g = 0.2\n"
                                         "period_min = 1.0\nperiod_max = 6.0\n"));
  try {
    (void)suite_scaling(far);
    ADD_FAILURE() << "scaled over [1, 6] s";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ensemble.scaling: "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("[0, 4] s"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace poundsim::io
