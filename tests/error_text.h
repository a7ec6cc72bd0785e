// The message of the exception a call throws, for tests of one-line errors that name the file and
// what was wrong; "(no exception)" when it throws none.
#pragma once

#include <gtest/gtest.h>

#include <exception>
#include <functional>
#include <string>

namespace semsegmap::test_support {

inline std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no exception)";
}

}  // namespace semsegmap::test_support

#define EXPECT_MENTIONS(message, text) \
  EXPECT_NE((message).find(text), std::string::npos) << "message: " << (message)
#define EXPECT_ONE_LINE(message) \
  EXPECT_EQ((message).find('\n'), std::string::npos) << "message: " << (message)
