// Result<T> and Result<void> (types/result.h): the error style of everything outside the core.
#include "types/result.h"

#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "host/can_endpoint.h"

namespace motwin {
namespace {

Result<int> half_of(int even) {
  if (even % 2 != 0) return Error{std::to_string(even) + " is odd"};
  return even / 2;
}

Result<void> check_positive(int number) {
  if (number <= 0) return Error{"not positive"};
  return {};
}

TEST(Result, holds_a_value_or_a_message) {
  const Result<int> half = half_of(42);
  ASSERT_TRUE(half.ok());
  EXPECT_TRUE(static_cast<bool>(half));
  EXPECT_EQ(half.value(), 21);
  EXPECT_EQ(*half, 21);
  EXPECT_EQ(half.error(), "");

  const Result<int> odd = half_of(7);
  EXPECT_FALSE(odd.ok());
  EXPECT_FALSE(static_cast<bool>(odd));
  EXPECT_EQ(odd.error(), "7 is odd");
}

TEST(Result, void_is_success_or_a_message) {
  const Result<void> fine = check_positive(3);
  EXPECT_TRUE(fine.ok());
  EXPECT_EQ(fine.error(), "");
  const Result<void> refused = check_positive(0);
  EXPECT_FALSE(refused.ok());
  EXPECT_EQ(refused.error(), "not positive");
}

TEST(Result, a_message_takes_the_context_of_the_caller_in_front) {
  EXPECT_EQ(half_of(5).error_with_context("--half: ").message, "--half: 5 is odd");
  EXPECT_EQ(check_positive(-1).error_with_context("--count: ").message, "--count: not positive");
  EXPECT_EQ(Error{"bad"}.with_context("x: ").message, "x: bad");
}

TEST(Result, carries_move_only_values) {
  Result<std::unique_ptr<int>> owned = std::make_unique<int>(5);
  ASSERT_TRUE(owned);
  std::unique_ptr<int> taken = std::move(*owned);
  ASSERT_NE(taken, nullptr);
  EXPECT_EQ(*taken, 5);
  EXPECT_EQ(*owned, nullptr);
}

TEST(ResultDeathTest, reading_the_value_of_a_failure_stops_the_process_with_a_message) {
  EXPECT_DEATH((void)half_of(3).value(), "value\\(\\) of a failed Result");
}

TEST(Result, parse_errors_name_the_part_that_failed) {
  // A TCP endpoint error inside a --can specification says which transport it belongs to.
  const Result<host::CanEndpointSpec> spec = host::parse_can_endpoint("socketcand:1.2.3.4:99999");
  EXPECT_FALSE(spec);
  EXPECT_EQ(spec.error(), "socketcand: expected HOST:PORT with a port from 0 to 65535, got \"1.2.3.4:99999\"");
  const Result<host::CanEndpointSpec> slcan = host::parse_can_endpoint("slcan-tcp:[::1]");
  EXPECT_EQ(slcan.error(), "slcan-tcp: expected [IPV6]:PORT, got \"[::1]\"");
}

}  // namespace
}  // namespace motwin
