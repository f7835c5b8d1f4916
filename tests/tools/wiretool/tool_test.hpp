// Test helper: a gtest fixture that runs the built wiretool binary (WIRETOOL_PATH) in a fresh directory of its
// own per test, capturing the exit status and standard error.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <utility>

namespace wiretool_test {

struct ToolRun {
    int status = -1;
    std::string err;
};

class ToolTest : public ::testing::Test {
protected:
    /// `name` prefixes the test directory; `subcommand` (e.g. "view ") is put before every run's arguments.
    ToolTest(std::string name, std::string subcommand) : name_(std::move(name)), subcommand_(std::move(subcommand)) {}

    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               (name_ + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::remove_all(dir_);
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }

    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    std::string write(const std::string& name, const std::string& text) const {
        std::ofstream(path(name)) << text;
        return path(name);
    }
    /// Runs `wiretool <subcommand><args>`; its standard error is captured beside the test directory, so the
    /// directory holds only what the tool wrote.
    ToolRun run(const std::string& args) const {
        const std::string err = (dir_.parent_path() / (dir_.filename().string() + "_stderr.txt")).string();
        const std::string cmd = std::string(WIRETOOL_PATH) + " " + subcommand_ + args + " 2> " + err + " > /dev/null";
        ToolRun r;
        const int raw = std::system(cmd.c_str());
        r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
        std::ifstream in(err);
        std::stringstream ss;
        ss << in.rdbuf();
        r.err = ss.str();
        std::filesystem::remove(err);
        return r;
    }

    std::filesystem::path dir_;

private:
    std::string name_, subcommand_;
};

}  // namespace wiretool_test
