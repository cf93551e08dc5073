// Scratch paths in the temporary directory that carry the test process's id, so that two checkouts (or two test
// processes) testing at once neither share nor remove each other's files.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace phiq::test {

// TMP/NAME_PID
inline std::filesystem::path scratch_path(const std::string& name) {
  return std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
}

// scratch_path(PREFIX + the running test's name)
inline std::filesystem::path test_scratch_path(const std::string& prefix) {
  return scratch_path(prefix + ::testing::UnitTest::GetInstance()->current_test_info()->name());
}

}  // namespace phiq::test
