// A fresh, empty folder per test, named after it; removed afterwards unless the test failed, so
// that what a failing test wrote can be looked at.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace drt::test {

class TempFolderTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = std::filesystem::temp_directory_path() /
               ("drt_" + std::string(info->test_suite_name()) + "_" + std::to_string(getpid()) +
                "_" + info->name());
        std::filesystem::remove_all(dir_);
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override {
        if (!HasFailure()) std::filesystem::remove_all(dir_);
    }

    std::filesystem::path dir_;
};

}  // namespace drt::test
