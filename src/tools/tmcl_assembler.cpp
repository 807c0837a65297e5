#include "tools/tmcl_assembler.h"

#include <algorithm>
#include <cctype>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <new>
#include <unordered_map>
#include <utility>

#include <fmt/format.h>

#include "tools/text.h"
#include "tools/tmcl_binary.h"
#include "tools/tmcl_mnemonics.h"

namespace motwin::tools {
namespace {

// An include chain deeper than this is treated as a cycle: it catches cycles that lexical path
// comparison cannot see (a symbolic link to a directory above).
constexpr size_t kMaxIncludeDepth = 32;

constexpr int64_t kValueMin = std::numeric_limits<int32_t>::min();
constexpr int64_t kValueMax = std::numeric_limits<uint32_t>::max();

// The axis names every TMCL-IDE program may use (docs/tmcl-protocol.md "TMCL-IDE program syntax";
// TMCLParam.tmc defines them too, with the same values, which is allowed).
constexpr std::string_view kBuiltInMotors[] = {"Motor0", "Motor1", "Motor2", "Motor3", "Motor4", "Motor5"};

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }
bool is_identifier_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) != 0 || c == '_'; }
bool is_identifier_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; }

size_t skip_blanks(std::string_view text, size_t position) {
  while (position < text.size() && is_blank(text[position])) ++position;
  return position;
}

// Length of the identifier at `position` (0: none).
size_t identifier_length(std::string_view text, size_t position) {
  if (position >= text.size() || !is_identifier_start(text[position])) return 0;
  size_t end = position + 1;
  while (end < text.size() && is_identifier_char(text[end])) ++end;
  return end - position;
}

std::string_view trim_end(std::string_view text) {
  while (!text.empty() && is_blank(text.back())) text.remove_suffix(1);
  return text;
}

std::string upper(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

std::string_view kind_name(SymbolKind kind) { return kind == SymbolKind::kLabel ? "label" : "constant"; }

std::string location_text(const SourceLocation& location) {
  if (location.line == 0) return location.file;
  if (location.column == 0) return fmt::format("{}:{}", location.file, location.line);
  return fmt::format("{}:{}:{}", location.file, location.line, location.column);
}

AssemblyErrorKind to_assembly_error(ParseErrorKind kind) {
  switch (kind) {
    case ParseErrorKind::kSyntax:
      return AssemblyErrorKind::kSyntax;
    case ParseErrorKind::kUnknownMnemonic:
      return AssemblyErrorKind::kUnknownMnemonic;
    case ParseErrorKind::kOperandCount:
      return AssemblyErrorKind::kOperandCount;
    case ParseErrorKind::kUnknownIdentifier:
      return AssemblyErrorKind::kUndefinedSymbol;
    case ParseErrorKind::kOutOfRange:
      return AssemblyErrorKind::kOutOfRange;
  }
  return AssemblyErrorKind::kSyntax;
}

// Splits a file into lines: "\n", "\r\n" and a final line without a break.
std::vector<std::string> split_lines(std::string_view content) {
  std::vector<std::string> lines;
  size_t start = 0;
  while (start < content.size()) {
    size_t end = content.find('\n', start);
    if (end == std::string_view::npos) end = content.size();
    std::string_view line = content.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    lines.emplace_back(line);
    start = end + 1;
  }
  return lines;
}

// Case-insensitive edit distance, for "did you mean" hints.
size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      const bool same =
          std::toupper(static_cast<unsigned char>(a[i - 1])) == std::toupper(static_cast<unsigned char>(b[j - 1]));
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

class Assembler {
 public:
  explicit Assembler(const AssemblerOptions& options) : options_(options) {
    if (!options_.reader) options_.reader = file_system_reader();
  }

  AssemblyResult run(const std::string& file_name, const std::optional<std::string>& source) {
    for (size_t i = 0; i < std::size(kBuiltInMotors); ++i) {
      define(kBuiltInMotors[i], SymbolKind::kConstant, static_cast<int64_t>(i), SourceLocation{}, true);
    }
    std::optional<std::string> content = source;
    if (!content) content = options_.reader(file_name);
    in_memory_main_ = source.has_value();
    if (!content) {
      error(AssemblyErrorKind::kFileNotFound, {file_name, 0, 0}, "cannot read the file");
    } else {
      main_file_ = std::filesystem::path(file_name).lexically_normal().string();
      include_chain_.push_back(main_file_);
      main_content_ = *content;
      read_file(main_file_, main_content_);
      include_chain_.pop_back();
      check_program_size();
      encode_instructions();
      append_stop();
    }
    return finish();
  }

 private:
  // An instruction line waiting for pass 2, when every label is known.
  struct PendingInstruction {
    size_t listing_index;
    size_t column;  // 0-based start of the instruction text in the line
  };

  // --- Errors and symbols ------------------------------------------------------------------

  void error(AssemblyErrorKind kind, SourceLocation location, std::string message) {
    errors_.push_back({errors_.size(), order_, {kind, std::move(location), std::move(message)}});
  }

  SourceLocation at(size_t column) const { return {current_file_, current_line_, static_cast<int>(column) + 1}; }

  void define(std::string_view name, SymbolKind kind, int64_t value, SourceLocation location, bool built_in = false) {
    const std::string key = upper(name);
    if (const auto found = symbol_index_.find(key); found != symbol_index_.end()) {
      const SymbolDefinition& existing = symbols_[found->second];
      // Repeating a constant with the same value is harmless (TMCLParam.tmc repeats the built-in
      // Motor0..Motor5; two files may include the same constants file).
      if (kind == SymbolKind::kConstant && existing.kind == SymbolKind::kConstant && existing.value == value) return;
      const std::string where =
          existing.built_in ? std::string("built in") : "defined at " + location_text(existing.location);
      const std::string existing_value = existing.kind == SymbolKind::kLabel ? fmt::format("address {}", existing.value)
                                                                             : std::to_string(existing.value);
      error(AssemblyErrorKind::kDuplicateSymbol, std::move(location),
            fmt::format("duplicate {} '{}': already a {} ({}, {}){}", kind_name(kind), name, kind_name(existing.kind),
                        existing_value, where,
                        kind == SymbolKind::kConstant && existing.kind == SymbolKind::kConstant
                            ? "; a constant may only be repeated with the same value"
                            : ""));
      return;
    }
    symbol_index_.emplace(key, symbols_.size());
    symbols_.push_back({std::string(name), kind, value, std::move(location), built_in});
  }

  // "; did you mean 'Loop'?" when a defined name is close to `name` (at most 2 edits, and
  // fewer than half of its letters).
  std::string suggestion(std::string_view name) const {
    const SymbolDefinition* best = nullptr;
    size_t best_distance = std::min<size_t>(3, (name.size() + 1) / 2);
    for (const SymbolDefinition& symbol : symbols_) {
      const size_t distance = edit_distance(name, symbol.name);
      if (distance < best_distance) {
        best = &symbol;
        best_distance = distance;
      }
    }
    return best == nullptr ? std::string() : fmt::format("; did you mean '{}'?", best->name);
  }

  std::optional<int64_t> lookup(std::string_view name) const {
    const auto found = symbol_index_.find(upper(name));
    if (found == symbol_index_.end()) return std::nullopt;
    return symbols_[found->second].value;
  }

  // --- Pass 1: lines, includes, labels and constants -----------------------------------------

  void read_file(const std::string& name, std::string_view content) {
    // Windows editors may start a UTF-8 file with a byte order mark.
    if (content.starts_with("\xEF\xBB\xBF")) content.remove_prefix(3);
    const std::vector<std::string> lines = split_lines(content);
    for (size_t i = 0; i < lines.size(); ++i) {
      current_file_ = name;
      current_line_ = static_cast<int>(i) + 1;
      order_ = listing_.size();
      listing_.push_back({{name, current_line_, 0}, lines[i], std::nullopt, {}, false});
      read_line(name, lines[i], listing_.size() - 1);
    }
  }

  void read_line(const std::string& file_name, std::string_view line, size_t listing_index) {
    std::string_view code = line;
    if (const size_t comment = code.find("//"); comment != std::string_view::npos) code = code.substr(0, comment);
    code = trim_end(code);
    size_t position = skip_blanks(code, 0);
    if (position == code.size()) return;

    if (code[position] == '#') {
      read_directive(file_name, code, position);
      return;
    }

    // Labels: "Name:" (several may precede one instruction).
    bool has_label = false;
    size_t label_column = 0;
    for (;;) {
      const size_t length = identifier_length(code, position);
      if (length == 0) break;
      const size_t colon = skip_blanks(code, position + length);
      if (colon >= code.size() || code[colon] != ':') break;
      define(code.substr(position, length), SymbolKind::kLabel, static_cast<int64_t>(address_), at(position));
      has_label = true;
      label_column = position;
      position = skip_blanks(code, colon + 1);
    }
    if (position == code.size()) return;

    if (code.find('=', position) != std::string_view::npos) {
      if (has_label) {
        error(AssemblyErrorKind::kSyntax, at(label_column),
              "a label must be followed by an instruction, not by a constant definition");
        return;
      }
      read_constant(code, position);
      return;
    }
    if (code[position] == '#') {
      error(AssemblyErrorKind::kSyntax, at(position), "a label must be followed by an instruction, not by a directive");
      return;
    }
    pending_.push_back({listing_index, position});
    listing_[listing_index].address = static_cast<uint32_t>(address_);
    ++address_;
  }

  // "Name = value": value is a number or a label or constant defined above.
  void read_constant(std::string_view code, size_t position) {
    const size_t equals = code.find('=', position);
    const size_t name_length = identifier_length(code, position);
    if (name_length == 0 || skip_blanks(code, position + name_length) != equals) {
      error(AssemblyErrorKind::kSyntax, at(position),
            "expected 'Name = value' (a name is a letter or '_' followed by letters, digits or '_')");
      return;
    }
    const std::string_view name = code.substr(position, name_length);
    const size_t value_start = skip_blanks(code, equals + 1);
    if (value_start == code.size()) {
      error(AssemblyErrorKind::kSyntax, at(equals), fmt::format("expected a value after '{} ='", name));
      return;
    }
    const std::string_view value_text = code.substr(value_start);
    const auto blank = std::find_if(value_text.begin(), value_text.end(), is_blank);
    if (blank != value_text.end() || value_text.find('=') != std::string_view::npos) {
      error(AssemblyErrorKind::kSyntax, at(value_start),
            fmt::format("expected one number or name after '{} =', got '{}' (expressions are not supported)", name,
                        value_text));
      return;
    }
    std::optional<int64_t> value = parse_integer(value_text);
    if (!value) {
      if (identifier_length(value_text, 0) != value_text.size()) {
        error(AssemblyErrorKind::kSyntax, at(value_start),
              fmt::format("'{}' is not a number (decimal or 0x hexadecimal) or a name", value_text));
        return;
      }
      value = lookup(value_text);
      if (!value) {
        error(AssemblyErrorKind::kUndefinedSymbol, at(value_start),
              fmt::format("undefined label or constant '{}': the value of a constant is a number or a name defined "
                          "above{}",
                          value_text, suggestion(value_text)));
        return;
      }
    }
    if (*value < kValueMin || *value > kValueMax) {
      error(AssemblyErrorKind::kOutOfRange, at(value_start),
            fmt::format("constant '{}': {} is out of range for a 32-bit value ({}..{})", name, *value, kValueMin,
                        kValueMax));
      return;
    }
    define(name, SymbolKind::kConstant, *value, at(position));
  }

  void read_directive(const std::string& file_name, std::string_view code, size_t position) {
    const size_t word_start = position + 1;
    size_t word_end = word_start;
    while (word_end < code.size() && std::isalpha(static_cast<unsigned char>(code[word_end])) != 0) ++word_end;
    const std::string_view directive = code.substr(word_start, word_end - word_start);
    if (!equals_ignore_case(directive, "include")) {
      error(AssemblyErrorKind::kSyntax, at(position),
            fmt::format("unknown directive '#{}': expected #include", directive));
      return;
    }
    const size_t name_start = skip_blanks(code, word_end);
    std::string_view include_name = code.substr(name_start);
    if (include_name.size() >= 2 && ((include_name.front() == '"' && include_name.back() == '"') ||
                                     (include_name.front() == '<' && include_name.back() == '>'))) {
      include_name = include_name.substr(1, include_name.size() - 2);
    }
    if (include_name.empty() ||
        (word_end < code.size() && !is_blank(code[word_end]) && code[word_end] != '"' && code[word_end] != '<')) {
      error(AssemblyErrorKind::kSyntax, at(name_start), "expected a file name after #include");
      return;
    }
    include(file_name, std::string(include_name), at(name_start));
  }

  void include(const std::string& including_file, const std::string& include_name, const SourceLocation& location) {
    namespace fs = std::filesystem;
    std::vector<std::string> candidates;
    const fs::path name(include_name);
    if (name.is_absolute()) {
      candidates.push_back(name.lexically_normal().string());
    } else {
      candidates.push_back((fs::path(including_file).parent_path() / name).lexically_normal().string());
      for (const std::string& directory : options_.include_dirs) {
        candidates.push_back((fs::path(directory) / name).lexically_normal().string());
      }
    }
    for (const std::string& candidate : candidates) {
      // A source given in memory exists under its name for #include too (a cycle to report).
      std::optional<std::string> content = in_memory_main_ && candidate == main_file_
                                               ? std::optional<std::string>(main_content_)
                                               : options_.reader(candidate);
      if (!content) continue;
      const bool cyclic = std::find(include_chain_.begin(), include_chain_.end(), candidate) != include_chain_.end();
      if (cyclic || include_chain_.size() >= kMaxIncludeDepth) {
        std::string chain;
        for (const std::string& file : include_chain_) chain += file + " -> ";
        error(AssemblyErrorKind::kIncludeCycle, location,
              cyclic ? fmt::format("include cycle: {}{}", chain, candidate)
                     : fmt::format("includes nested deeper than {} files (a cycle?): {}{}", kMaxIncludeDepth, chain,
                                   candidate));
        return;
      }
      include_chain_.push_back(candidate);
      read_file(candidate, *content);
      include_chain_.pop_back();
      return;
    }
    std::string searched;
    for (const std::string& candidate : candidates) searched += (searched.empty() ? "" : ", ") + candidate;
    error(AssemblyErrorKind::kIncludeNotFound, location,
          fmt::format("include file '{}' not found (searched {}{})", include_name, searched,
                      options_.include_dirs.empty() ? "; add a directory with -I" : ""));
  }

  // --- Pass 2: encoding ----------------------------------------------------------------------

  void check_program_size() {
    const size_t total = address_ + (options_.append_stop ? 1 : 0);
    if (total <= options_.program_memory_size) return;
    const std::string message =
        fmt::format("the program needs {} instructions{}, but program memory holds {}", total,
                    options_.append_stop ? " (with the STOP appended at its end)" : "", options_.program_memory_size);
    // Point at the first instruction that does not fit (the appended STOP: the last line).
    for (const PendingInstruction& pending : pending_) {
      if (*listing_[pending.listing_index].address == options_.program_memory_size) {
        const ListingLine& line = listing_[pending.listing_index];
        order_ = pending.listing_index;
        error(AssemblyErrorKind::kProgramTooLong,
              {line.location.file, line.location.line, static_cast<int>(pending.column) + 1}, message);
        return;
      }
    }
    order_ = listing_.size();
    const std::string file = listing_.empty() ? main_file_ : listing_.back().location.file;
    error(AssemblyErrorKind::kProgramTooLong, {file, listing_.empty() ? 0 : listing_.back().location.line, 0}, message);
  }

  void encode_instructions() {
    instructions_.assign(address_, tmcl::Instruction{});
    for (const PendingInstruction& pending : pending_) {
      ListingLine& line = listing_[pending.listing_index];
      order_ = pending.listing_index;
      const std::string_view text = std::string_view(line.text).substr(pending.column);
      ParseErrorDetail detail;
      ParseOptions parse_options;
      parse_options.resolve_identifier = [this](std::string_view name) { return lookup(name); };
      parse_options.error_detail = &detail;
      Result<tmcl::Instruction> instruction = parse_instruction(text, parse_options);
      if (!instruction) {
        std::string message = instruction.error();
        if (detail.kind == ParseErrorKind::kUnknownIdentifier) {
          message += suggestion(text.substr(detail.offset, detail.length));
        }
        error(to_assembly_error(detail.kind),
              {line.location.file, line.location.line, static_cast<int>(pending.column + detail.offset) + 1},
              std::move(message));
        continue;
      }
      line.instruction = instruction.value();
      instructions_[*line.address] = instruction.value();
    }
  }

  void append_stop() {
    if (!options_.append_stop) return;
    const tmcl::Instruction stop{tmcl::command::kStop, 0, 0, 0};
    listing_.push_back({{}, "STOP", static_cast<uint32_t>(address_), stop, true});
    instructions_.push_back(stop);
  }

  AssemblyResult finish() {
    AssemblyResult result;
    // Source order: pass-2 errors belong before the pass-1 errors of later lines.
    std::stable_sort(errors_.begin(), errors_.end(), [](const OrderedError& a, const OrderedError& b) {
      if (a.order != b.order) return a.order < b.order;
      if (a.error.location.column != b.error.location.column) return a.error.location.column < b.error.location.column;
      return a.sequence < b.sequence;
    });
    for (OrderedError& ordered : errors_) result.errors.push_back(std::move(ordered.error));
    result.instructions = std::move(instructions_);
    result.listing = std::move(listing_);
    result.symbols = std::move(symbols_);
    return result;
  }

  struct OrderedError {
    size_t sequence;
    size_t order;  // listing index of the line
    AssemblyError error;
  };

  AssemblerOptions options_;
  std::string main_file_;
  std::string main_content_;
  bool in_memory_main_ = false;
  std::vector<std::string> include_chain_;
  std::string current_file_;
  int current_line_ = 0;
  size_t order_ = 0;
  size_t address_ = 0;
  std::vector<ListingLine> listing_;
  std::vector<PendingInstruction> pending_;
  std::vector<SymbolDefinition> symbols_;
  std::unordered_map<std::string, size_t> symbol_index_;
  std::vector<tmcl::Instruction> instructions_;
  std::vector<OrderedError> errors_;
};

AssemblyResult assemble(const std::string& file_name, const std::optional<std::string>& source,
                        const AssemblerOptions& options) {
  const auto internal_error = [&](std::string_view what) {
    AssemblyResult result;
    result.errors.push_back({AssemblyErrorKind::kInternal, {file_name, 0, 0}, fmt::format("internal error: {}", what)});
    return result;
  };
  try {
    return Assembler(options).run(file_name, source);
  } catch (const std::exception& exception) {
    return internal_error(exception.what());
  } catch (...) {
    return internal_error("unknown exception");
  }
}

}  // namespace

std::string format_error(const AssemblyError& error) {
  return fmt::format("{}: error: {}", location_text(error.location), error.message);
}

const SymbolDefinition* AssemblyResult::find_symbol(std::string_view name) const {
  const auto found = std::find_if(symbols.begin(), symbols.end(), [&](const SymbolDefinition& symbol) {
    return equals_ignore_case(symbol.name, name);
  });
  return found == symbols.end() ? nullptr : &*found;
}

std::optional<uint32_t> AssemblyResult::label_address(std::string_view name) const {
  const SymbolDefinition* symbol = find_symbol(name);
  if (symbol == nullptr || symbol->kind != SymbolKind::kLabel) return std::nullopt;
  return static_cast<uint32_t>(symbol->value);
}

SourceReader file_system_reader() {
  return [](const std::string& path) -> std::optional<std::string> {
    std::error_code error;
    if (!std::filesystem::is_regular_file(path, error)) return std::nullopt;
    std::ifstream in(path, std::ios::binary);
    if (!in) return std::nullopt;
    std::string content{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    if (in.bad()) return std::nullopt;
    return content;
  };
}

AssemblyResult assemble_file(const std::string& path, const AssemblerOptions& options) {
  return assemble(path, std::nullopt, options);
}

AssemblyResult assemble_source(std::string_view source, const std::string& file_name, const AssemblerOptions& options) {
  try {
    return assemble(file_name, std::string(source), options);
  } catch (...) {  // std::bad_alloc copying the source
    AssemblyResult result;
    result.errors.push_back({AssemblyErrorKind::kInternal, {}, "internal error: out of memory"});
    return result;
  }
}

std::string format_listing(const AssemblyResult& result) {
  std::string out = fmt::format("{:>4}  {:<23}  {:>4}  {}\n", "ADDR", "BYTES", "LINE", "SOURCE");
  const std::string* current_file = nullptr;
  for (const ListingLine& line : result.listing) {
    if (!line.appended && (current_file == nullptr || *current_file != line.location.file)) {
      current_file = &line.location.file;
      out += fmt::format("{:>4}  {:<23}  {:>4}  === {} ===\n", "", "", "", line.location.file);
    }
    std::string address;
    std::string bytes;
    if (line.address) {
      address = std::to_string(*line.address);
      const BinaryRecord record = encode_binary_record(line.instruction);
      for (size_t i = 0; i < record.size(); ++i) bytes += fmt::format("{}{:02X}", i == 0 ? "" : " ", record[i]);
    }
    if (line.appended) {
      out += fmt::format("{:>4}  {:<23}  {:>4}  {}\n", address, bytes, "", "STOP  (appended by the assembler)");
    } else {
      out += fmt::format("{:>4}  {:<23}  {:>4}  {}\n", address, bytes, line.location.line, line.text);
    }
  }
  // Trailing blanks of empty source lines are noise.
  std::string trimmed;
  size_t start = 0;
  while (start < out.size()) {
    const size_t end = out.find('\n', start);
    trimmed += trim_end(std::string_view(out).substr(start, end - start));
    trimmed += '\n';
    start = end + 1;
  }
  return trimmed;
}

std::string format_symbols(const AssemblyResult& result) {
  std::string out;
  for (const SymbolKind kind : {SymbolKind::kLabel, SymbolKind::kConstant}) {
    for (const SymbolDefinition& symbol : result.symbols) {
      if (symbol.built_in || symbol.kind != kind) continue;
      out += fmt::format("{} {} {} {}:{}\n", kind_name(kind), symbol.name, symbol.value, symbol.location.file,
                         symbol.location.line);
    }
  }
  return out;
}

}  // namespace motwin::tools
