#!/usr/bin/env bash
# Proves the core is firmware-like (docs/architecture.md "Rules the core keeps"): the archive
# references no OS call, no heap, no exceptions and no RTTI, and no core source includes an OS or
# I/O header.
# Usage: check_core_freestanding.sh <libmotwin_core.a> <src/core dir>
set -euo pipefail
archive=$1
core_dir=$2
status=0

# Undefined symbols the core may use: freestanding C library and libm functions (and the
# sanitizer runtime hooks in the ASan + UBSan build).
allowed='^(__asan_[a-z0-9_]+|__ubsan_[a-z0-9_]+|__sanitizer_[a-z0-9_]+|memcpy|memmove|memset|memcmp|strlen|sqrt|sqrtf|fabs|llround|lround|round|floor|ceil|sin|cos|sinf|cosf|sincos|sincosf|atan2|atan2f|fmod|exp|log|pow|copysign|copysignf|__stack_chk_fail|_GLOBAL_OFFSET_TABLE_|__dso_handle|__cxa_pure_virtual|__cxa_guard_acquire|__cxa_guard_release|__cxa_guard_abort|__cxa_atexit)$'
undefined=$(nm --undefined-only --format=just-symbols "$archive" | sort -u)
bad=$(echo "$undefined" | grep -v -E '^$' | grep -v -E "$allowed" || true)
# Core objects refer to each other; those are defined somewhere in the archive.
defined=$(nm --defined-only --format=just-symbols "$archive" | sort -u)
really_bad=$(comm -23 <(echo "$bad" | sort -u) <(echo "$defined") || true)
if [ -n "$really_bad" ]; then
  echo "core references symbols outside the freestanding allowlist:"
  echo "$really_bad" | c++filt
  status=1
fi

forbidden_headers='#include <(iostream|fstream|sstream|cstdio|stdio\.h|thread|mutex|chrono|filesystem|unistd\.h|fcntl\.h|sys/.*|poll\.h|signal\.h|csignal|string|vector|map|unordered_map|memory|functional|stdexcept|exception|typeinfo|random|ctime|time\.h)>'
if grep -R -n -E "$forbidden_headers" "$core_dir"; then
  echo "core includes an OS, I/O or allocating header"
  status=1
fi
if grep -R -n -E '\b(new|delete|throw|try|catch|dynamic_cast|typeid)\b' --include='*.cpp' --include='*.h' "$core_dir" | grep -v -E '//.*\b(new|delete|throw|try|catch)\b' | grep -v -E '= delete|"[^"]*\b(new|delete)\b[^"]*"'; then
  echo "core uses the heap, exceptions or RTTI"
  status=1
fi
[ $status -eq 0 ] && echo "core is freestanding: $(echo "$undefined" | grep -c . || true) external symbols, all allowed"
exit $status
