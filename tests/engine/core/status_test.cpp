// engine/core: Status (success is an empty message; a failure names what is wrong and the item to blame) and
// Expected<T> (a value or a failed Status), as every module uses them.
#include "engine/core/expected.hpp"
#include "engine/core/status.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <string>

namespace {

engine::Status check_positive(double x, int index) {
    if (!(x > 0.0)) return engine::Status::error("node " + std::to_string(index) + ": must be positive", index);
    return engine::Status::success();
}

engine::Expected<std::unique_ptr<int>> make(int v) {
    if (v < 0) return engine::Error{"negative: " + std::to_string(v)};
    return std::make_unique<int>(v);
}

TEST(Status, SuccessAndFailure) {
    const engine::Status ok = check_positive(1.0, 3);
    EXPECT_TRUE(ok.ok());
    EXPECT_TRUE(static_cast<bool>(ok));
    EXPECT_TRUE(ok.message.empty());
    EXPECT_EQ(ok.index, -1);
    const engine::Status bad = check_positive(-2.0, 3);
    EXPECT_FALSE(bad.ok());
    EXPECT_FALSE(static_cast<bool>(bad));
    EXPECT_EQ(bad.message, "node 3: must be positive");
    EXPECT_EQ(bad.index, 3);
    EXPECT_TRUE(engine::Status{}.ok()) << "default is success";
}

TEST(Expected, ValueOrFailure) {
    auto good = make(7);
    ASSERT_TRUE(good.ok());
    EXPECT_EQ(**good, 7);
    std::unique_ptr<int> taken = std::move(good).value();
    EXPECT_EQ(*taken, 7);
    const auto bad = make(-1);
    ASSERT_FALSE(bad.ok());
    EXPECT_FALSE(static_cast<bool>(bad));
    EXPECT_EQ(bad.error().message, "negative: -1");
    EXPECT_EQ(bad.error().index, -1);
}

}  // namespace
