// Generic operations over a module's parameter table: lookup, access letters and ranges.
// Every TMCL command that touches a parameter goes through here, so the rules of the
// manuals' access columns live in one place.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "core/params/parameter.h"
#include "core/tmcl/status.h"

namespace motwin::params {

template <class Owner>
class ParameterTable {
 public:
  using Row = ParameterRow<Owner>;

  constexpr explicit ParameterTable(std::span<const Row> rows) : rows_(rows) {}

  constexpr std::span<const Row> rows() const { return rows_; }

  // Rows are sorted by number (each module builds its tables with sorted_table()).
  constexpr const Row* find(uint16_t number) const {
    size_t lo = 0;
    size_t hi = rows_.size();
    while (lo < hi) {
      const size_t mid = lo + (hi - lo) / 2;
      if (rows_[mid].info.number == number) return &rows_[mid];
      if (rows_[mid].info.number < number) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
    return nullptr;
  }

  constexpr bool is_sorted() const {
    for (size_t i = 1; i < rows_.size(); ++i) {
      if (rows_[i - 1].info.number >= rows_[i].info.number) return false;
    }
    return true;
  }

  // Unknown parameter and unreadable parameter: status 3 (wrong type).
  tmcl::Status read(Owner& owner, uint8_t axis, uint16_t number, int32_t& value) const {
    const Row* row = find(number);
    if (row == nullptr || !has(row->info.access, Access::kRead) || row->binding.get == nullptr) {
      return tmcl::Status::kWrongType;
    }
    value = row->binding.get(owner, axis);
    return tmcl::Status::kOk;
  }

  // Unknown or read-only parameter: status 3 (wrong type, docs/decisions.md); value outside
  // the row's range: status 4 (invalid value). Nothing changes on error.
  tmcl::Status write(Owner& owner, uint8_t axis, uint16_t number, int32_t value) const {
    const Row* row = find(number);
    if (row == nullptr || !has(row->info.access, Access::kWrite) || row->binding.set == nullptr) {
      return tmcl::Status::kWrongType;
    }
    if (!in_range(row->info, value)) return tmcl::Status::kInvalidValue;
    return row->binding.set(owner, axis, value);
  }

 private:
  std::span<const Row> rows_;
};

// Deliberately not constexpr: reaching it during constant evaluation is a compile error.
void parameter_rows_not_sorted_by_number();

// A table over rows with static storage, checked at compile time to be sorted by number (find()
// bisects): `static constexpr Table kTable = sorted_table<Owner>(kRows);`.
template <class Owner>
consteval ParameterTable<Owner> sorted_table(std::span<const ParameterRow<Owner>> rows) {
  const ParameterTable<Owner> table{rows};
  if (!table.is_sorted()) parameter_rows_not_sorted_by_number();
  return table;
}

namespace detail {
template <class Rows>
struct RowCount;
template <class Row, size_t kCount>
struct RowCount<Row[kCount]> {
  static constexpr size_t value = kCount;
};
template <class Row, size_t kCount>
struct RowCount<std::array<Row, kCount>> {
  static constexpr size_t value = kCount;
};
}  // namespace detail

// One row list from several, in the order given: a module's own rows and the rows a base
// shares between modules (core/tmcl/tmcl_module.h). Parts are arrays or std::arrays of rows;
// the table over the result checks the order like any other.
template <class Owner, class... Parts>
constexpr auto join_rows(const Parts&... parts) {
  std::array<ParameterRow<Owner>, (detail::RowCount<Parts>::value + ...)> rows{};
  size_t next = 0;
  const auto append = [&](const auto& part) {
    for (const ParameterRow<Owner>& row : part) rows[next++] = row;
  };
  (append(parts), ...);
  return rows;
}

// How a generation of a module's firmware changes the rows of another (TMCM-1636 1.13 from
// 1.09): rows it no longer has, rows that keep their number and text but reach the module
// another way, rows it adds.
template <class Owner>
struct ReboundRow {
  uint16_t number;
  Binding<Owner> binding;
};

// Deliberately not constexpr: reaching it during constant evaluation is a compile error.
void revised_row_not_in_base();

// `base` without the numbers in `removed`, with the bindings of `rebound`, plus `added`, sorted by
// number (sorted_table() then checks that no number comes twice). Every removed or rebound number
// must be a row of `base`.
template <class Owner, size_t kResult>
consteval std::array<ParameterRow<Owner>, kResult> revised_rows(std::span<const ParameterRow<Owner>> base,
                                                                 std::span<const uint16_t> removed,
                                                                 std::span<const ReboundRow<Owner>> rebound,
                                                                 std::span<const ParameterRow<Owner>> added) {
  const auto in_base = [&](uint16_t number) {
    for (const ParameterRow<Owner>& row : base) {
      if (row.info.number == number) return true;
    }
    return false;
  };
  for (uint16_t number : removed) {
    if (!in_base(number)) revised_row_not_in_base();
  }
  for (const ReboundRow<Owner>& row : rebound) {
    if (!in_base(row.number)) revised_row_not_in_base();
  }
  std::array<ParameterRow<Owner>, kResult> rows{};
  size_t next = 0;
  for (const ParameterRow<Owner>& row : base) {
    bool dropped = false;
    for (uint16_t number : removed) dropped = dropped || number == row.info.number;
    if (dropped) continue;
    if (next == kResult) revised_row_not_in_base();  // kResult too small
    rows[next] = row;
    for (const ReboundRow<Owner>& change : rebound) {
      if (change.number == row.info.number) rows[next].binding = change.binding;
    }
    ++next;
  }
  for (const ParameterRow<Owner>& row : added) {
    if (next == kResult) revised_row_not_in_base();
    rows[next++] = row;
  }
  if (next != kResult) revised_row_not_in_base();  // kResult too large
  // Insertion sort by number.
  for (size_t i = 1; i < kResult; ++i) {
    for (size_t j = i; j > 0 && rows[j - 1].info.number > rows[j].info.number; --j) {
      const ParameterRow<Owner> swapped = rows[j];
      rows[j] = rows[j - 1];
      rows[j - 1] = swapped;
    }
  }
  return rows;
}

}  // namespace motwin::params
