// The real `motwin` binary run as a user runs it, for the tests of its commands.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "tools/child_process.h"

namespace motwin::testing {

// `motwin ARGUMENTS...` to completion (killed after 30 s): its exit status and its stdout and
// stderr together. A failure to run it at all fails the test and gives exit status -1.
inline tools::CompletedProcess run_motwin(std::vector<std::string> arguments) {
  arguments.insert(arguments.begin(), MOTWIN_BINARY);
  Result<tools::CompletedProcess> completed = tools::ChildProcess::run(arguments, std::chrono::seconds(30));
  if (!completed) ADD_FAILURE() << completed.error();
  return completed ? completed.value() : tools::CompletedProcess{-1, {}};
}

}  // namespace motwin::testing
