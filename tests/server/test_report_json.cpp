// report.json (proto/contract/report_json): the protobuf JSON mapping of a report with null for numbers
// never computed, stable bytes, and readable back by protobuf's own parser.
#include <gtest/gtest.h>
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>
#include <google/protobuf/util/message_differencer.h>

#include <cmath>
#include <limits>
#include <string>

#include "balloon/v1/balloon.pb.h"
#include "contract/report_json.hpp"

namespace balloon::contract {
namespace {

namespace v1 = balloon::v1;

v1::DesignReport design_with_errors() {
  v1::DesignReport report;
  report.set_converged(true);
  report.set_stop_reason("matched");
  report.set_avg_error_mm(0.25);
  report.set_max_error_mm(1.5);
  report.set_avg_error_rel(0.0025);
  report.set_max_error_rel(0.015);
  report.set_bbox_diag_mm(100.0);
  report.set_pressure_kpa(3.5);
  report.set_volume_ratio(8.0);
  report.set_distance_energy(0.01);
  report.set_residual_norm(1e-7);
  report.set_iterations(42);
  report.add_active_terms("distance");
  report.mutable_convergence()->add_time_s(0.1);
  report.mutable_convergence()->add_iteration(1);
  report.mutable_mold()->set_nozzle_vertex(7);
  report.mutable_mold()->set_tube_radius_mm(2.5);
  return report;
}

TEST(ReportJson, AnErrorNeverComputedIsNullAndAnInapplicableCountIsAbsent) {
  v1::DesignReport report;
  report.set_stop_reason("start_failed");
  report.set_mold_problem("the design produced no rest shape");
  const std::string json = report_json(report);
  for (const char* key : {"avg_error_mm", "max_error_mm", "avg_error_rel", "max_error_rel", "baseline_avg_error_mm",
                          "baseline_max_error_mm", "improvement_over_baseline", "pressure_kpa", "volume_ratio",
                          "distance_energy", "residual_norm"})
    EXPECT_NE(json.find(std::string("\"") + key + "\":null"), std::string::npos) << key << " in " << json;
  EXPECT_EQ(json.find("\"avg_error_mm\":0"), std::string::npos) << json;
  EXPECT_EQ(json.find("resumed_from_iteration"), std::string::npos) << "absent when the design ran through";
  EXPECT_EQ(json.find("\"mold\""), std::string::npos) << "no mold object without a mold";
  EXPECT_NE(json.find("\"mold_problem\":\"the design produced no rest shape\""), std::string::npos) << json;
  // Every other field is printed, zero or not, under its .proto name.
  EXPECT_NE(json.find("\"converged\":false"), std::string::npos) << json;
  EXPECT_NE(json.find("\"iterations\":0"), std::string::npos) << json;
  EXPECT_NE(json.find("\"active_terms\":[]"), std::string::npos) << json;
  EXPECT_EQ(json.front(), '{');
  EXPECT_EQ(json.back(), '\n');
  EXPECT_EQ(json.find('\n'), json.size() - 1) << "one line";
}

TEST(ReportJson, TheCheckFromRestIsAbsentWithoutADesignAndNullWhereItDidNotFinish) {
  EXPECT_EQ(report_json(v1::DesignReport()).find("from_rest"), std::string::npos) << "no check without a design";
  v1::DesignReport report = design_with_errors();
  v1::RestInflationCheck* check = report.mutable_from_rest();
  check->set_stop_reason("time_limit");
  check->set_message("inflated from rest, as balloon simulate does, it did not reach the design's volume: time limit");
  const std::string json = report_json(report);
  for (const char* key : {"avg_error_mm", "max_error_mm", "avg_error_rel", "pressure_kpa", "deviation_mm"})
    EXPECT_NE(json.find(std::string("\"") + key + "\":null", json.find("\"from_rest\"")), std::string::npos)
        << key << " in " << json;
  EXPECT_NE(json.find("\"from_rest\":{\"converged\":false,\"stop_reason\":\"time_limit\","), std::string::npos) << json;
  EXPECT_NE(json.find("\"another_shape\":false"), std::string::npos) << json;
}

TEST(ReportJson, ComputedValuesAndResumptionAreWritten) {
  v1::DesignReport report = design_with_errors();
  report.set_resumed_from_iteration(17);
  const std::string json = report_json(report);
  EXPECT_NE(json.find("\"avg_error_mm\":0.25,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"max_error_rel\":0.015,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"resumed_from_iteration\":17"), std::string::npos) << json;
  EXPECT_NE(json.find("\"mold\":{\"nozzle_vertex\":7,\"tube_radius_mm\":2.5,\"tube_length_mm\":0}"), std::string::npos)
      << json;
  EXPECT_NE(json.find("\"convergence\":{\"time_s\":[0.1],\"iteration\":[1],"), std::string::npos) << json;
  // Fields come in .proto order: converged first, the convergence log last.
  EXPECT_EQ(json.rfind("{\"converged\":true,\"stop_reason\":\"matched\",", 0), 0u) << json;
}

TEST(ReportJson, ProtobufReadsItBackToTheSameMessage) {
  for (const bool with_errors : {true, false}) {
    v1::DesignReport report = with_errors ? design_with_errors() : v1::DesignReport();
    report.set_message("quotes \" and \\ and a tab\t and \x01 and UTF-8 \xc3\xa9");
    v1::DesignReport read;
    const auto status = google::protobuf::util::JsonStringToMessage(report_json(report), &read);
    ASSERT_TRUE(status.ok()) << status.ToString() << "\n" << report_json(report);
    EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(read, report)) << read.DebugString();
    EXPECT_EQ(read.has_avg_error_mm(), with_errors) << "null reads back as absent";
  }
  v1::SimulateReport simulate;
  simulate.set_control("pressure");
  simulate.set_target_pressure_kpa(18.0);
  const std::string json = report_json(simulate);
  EXPECT_NE(json.find("\"target_pressure_kpa\":18,"), std::string::npos) << json;
  EXPECT_EQ(json.find("target_volume_ratio"), std::string::npos) << "the other member of the oneof is absent";
  v1::SimulateReport read;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(json, &read).ok());
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(read, simulate));
}

// Where every optional field is set, report.json holds what protobuf's own printer holds (MessageToJsonString
// with the .proto names and every field): the same keys with the same values, maps included.
TEST(ReportJson, IsProtobufsJsonMappingWhenNothingIsMissing) {
  v1::DesignReport design = design_with_errors();
  design.set_baseline_avg_error_mm(0.5);
  design.set_baseline_max_error_mm(2.0);
  design.set_baseline_avg_error_rel(0.005);
  design.set_improvement_over_baseline(2.0);
  design.set_resumed_from_iteration(3);
  design.set_mold_problem("");
  design.mutable_nozzle()->set_center_vertex(4);
  design.mutable_nozzle()->set_radius_mm(1.25);
  design.mutable_tolerance()->add_levels()->set_perturbation(0.1);
  v1::FitReport fit;
  v1::FitModelReport* model = fit.add_fits();
  (*model->mutable_params())["C1"] = 0.18;
  (*model->mutable_params())["C2"] = 0.02;
  model->add_sets()->set_label("a.csv");
  for (const google::protobuf::Message* report : {static_cast<const google::protobuf::Message*>(&design),
                                                  static_cast<const google::protobuf::Message*>(&fit)}) {
    google::protobuf::util::JsonPrintOptions options;
    options.preserve_proto_field_names = true;
    options.always_print_primitive_fields = true;
    std::string theirs;
    ASSERT_TRUE(google::protobuf::util::MessageToJsonString(*report, &theirs, options).ok());
    google::protobuf::Value ours_value, theirs_value;
    ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(report_json(*report), &ours_value).ok());
    ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(theirs, &theirs_value).ok());
    EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(ours_value, theirs_value))
        << "ours:   " << report_json(*report) << "theirs: " << theirs;
  }
}

TEST(ReportJson, MapsAreSortedAndNonFiniteNumbersAreNull) {
  v1::FitReport report;
  v1::FitModelReport* fit = report.add_fits();
  fit->set_model("hart-smith");
  // Inserted out of order: the bytes must not depend on the map's own (per-process) order.
  (*fit->mutable_params())["k2"] = 1.0;
  (*fit->mutable_params())["G"] = 0.1;
  (*fit->mutable_params())["k1"] = 3e-4;
  (*fit->mutable_std_errors())["G"] = std::numeric_limits<double>::infinity();
  const std::string json = report_json(report);
  EXPECT_NE(json.find("\"params\":{\"G\":0.1,\"k1\":3e-04,\"k2\":1}"), std::string::npos) << json;
  EXPECT_NE(json.find("\"std_errors\":{\"G\":null}"), std::string::npos) << json;
  EXPECT_EQ(json.find("Infinity"), std::string::npos) << json;
  EXPECT_EQ(report_json(report), json);
}

}  // namespace
}  // namespace balloon::contract
