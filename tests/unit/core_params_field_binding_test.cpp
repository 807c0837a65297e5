// params::field_binding over the field types a parameter row may bind: int32_t, uint32_t and
// enums over int32_t (the mode parameters), read and written as wire values.
#include <gtest/gtest.h>

#include <cstdint>

#include "core/params/parameter.h"

namespace motwin::params {
namespace {

enum class Mode : int32_t { kOff = 0, kSlow = 1, kFast = 4 };

struct Settings {
  int32_t count = -5;
  uint32_t loops = 0;
  Mode mode = Mode::kSlow;
};

struct Owner {
  Settings settings;
};

Settings& settings_of(Owner& owner) { return owner.settings; }

TEST(FieldBinding, an_enum_field_reads_and_writes_its_wire_number) {
  constexpr Binding<Owner> binding = field_binding<Owner, settings_of, &Settings::mode>();
  Owner owner;
  EXPECT_EQ(binding.get(owner, 0), 1);
  EXPECT_EQ(binding.set(owner, 0, 4), tmcl::Status::kOk);
  EXPECT_EQ(owner.settings.mode, Mode::kFast);
  EXPECT_EQ(binding.get(owner, 0), 4);
}

TEST(FieldBinding, an_enum_field_keeps_a_number_it_does_not_name) {
  constexpr Binding<Owner> binding = field_binding<Owner, settings_of, &Settings::mode>();
  Owner owner;
  EXPECT_EQ(binding.set(owner, 0, 3), tmcl::Status::kOk);
  EXPECT_EQ(static_cast<int32_t>(owner.settings.mode), 3);
  EXPECT_EQ(binding.get(owner, 0), 3);
}

TEST(FieldBinding, integer_fields_take_the_wire_bits_as_they_come) {
  constexpr Binding<Owner> count = field_binding<Owner, settings_of, &Settings::count>();
  constexpr Binding<Owner> loops = field_binding<Owner, settings_of, &Settings::loops, false>();
  Owner owner;
  EXPECT_EQ(count.set(owner, 0, INT32_MIN), tmcl::Status::kOk);
  EXPECT_EQ(owner.settings.count, INT32_MIN);
  owner.settings.loops = 4000000000u;
  EXPECT_EQ(static_cast<uint32_t>(loops.get(owner, 0)), 4000000000u);
  EXPECT_EQ(loops.set, nullptr);  // read-only
}

}  // namespace
}  // namespace motwin::params
