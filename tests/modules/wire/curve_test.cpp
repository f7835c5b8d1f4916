// Tests of the wire curve stage (nodes -> Curve), multiresolution and exact references.
#include <gtest/gtest.h>

#include "wire/curve.hpp"
#include "wire/status.hpp"

TEST(WireCurve, StatusDefaultIsOk) { EXPECT_TRUE(wire::Status{}.ok); }
