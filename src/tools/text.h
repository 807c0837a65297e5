// Small text helpers shared by the tools.
#pragma once

#include <algorithm>
#include <cctype>
#include <string_view>

namespace motwin::tools {

// ASCII case-insensitive equality: mnemonics, symbols, module and format names.
inline bool equals_ignore_case(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::toupper(static_cast<unsigned char>(x)) == std::toupper(static_cast<unsigned char>(y));
         });
}

}  // namespace motwin::tools
