// The files of a glove calibration (docs/glove-calibration.md): the procedure a user follows
// (PROC.json: the poses held and when, the pivot or the given tracker-to-hand offset) and the
// per-user result (USER.json: each sensor's offset, gain and coupling, the tracker-to-hand pose,
// the residuals), which a glove device in a scene names as "calibration". Errors name the file
// and the JSON pointer (hapsim::Error "<file>:<pointer>").
#pragma once

#include "hapsim/device/glove_calibration.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <string_view>

namespace hapsim {

inline constexpr std::string_view kGloveProcedureFormat = "hapsim-glove-procedure/1";
inline constexpr std::string_view kGloveCalibrationFormat = "hapsim-glove-calibration/1";

[[nodiscard]] GloveProcedure parse_glove_procedure(std::string_view text,
                                                   const std::filesystem::path& file);
[[nodiscard]] GloveProcedure load_glove_procedure(const std::filesystem::path& file);

/// USER.json's document for `calibration`; `raw_file` and `procedure_file` are recorded as its
/// source.
[[nodiscard]] nlohmann::json glove_calibration_json(const GloveCalibration& calibration,
                                                    const std::string& raw_file,
                                                    const std::string& procedure_file);

/// A calibration written by glove_calibration_json (its residuals kept for reports), finished
/// (finish_glove_calibration) and ready to convert counts.
[[nodiscard]] GloveCalibration parse_glove_calibration(std::string_view text,
                                                       const std::filesystem::path& file);
[[nodiscard]] GloveCalibration load_glove_calibration(const std::filesystem::path& file);

/// A glove trajectory file for a device: angle columns j0..j14 as they are; raw sensor columns
/// s0..s13 turned into angles by `calibration` (null: an error saying a calibration is needed).
/// An angle trajectory given with a calibration is an error too (the calibration would be
/// ignored). `calibration_file` names it in messages.
[[nodiscard]] Trajectory load_glove_trajectory(const std::filesystem::path& file,
                                               const GloveCalibration* calibration,
                                               const std::filesystem::path& calibration_file);

}  // namespace hapsim
