// Text value parsing: trimming, list delimiters, integers and booleans (guide section 3.1 item 5).
#include <catch2/catch_test_macros.hpp>

#include <cstdint>

#include "setting_text.h"

using namespace asval::settings_detail;
using Items = std::vector<std::string>;

TEST_CASE("TrimWhitespace strips the VUL whitespace set from both ends", "[settings][text]") {
  CHECK(TrimWhitespace(" \t\f\v\r\n a b \r\n") == "a b");
  CHECK(TrimWhitespace(" \t ").empty());
  CHECK(TrimWhitespace("x") == "x");
}

TEST_CASE("SplitList uses ',' when present, else ':'", "[settings][text]") {
  CHECK(SplitList("error,warn") == Items{"error", "warn"});
  CHECK(SplitList("error:warn") == Items{"error", "warn"});
  // A comma anywhere wins: colons are then part of the items.
  CHECK(SplitList("a:b,c") == Items{"a:b", "c"});
  CHECK(SplitList("single") == Items{"single"});
}

TEST_CASE("SplitList trims items and drops empty ones", "[settings][text]") {
  CHECK(SplitList(" error , warn ,") == Items{"error", "warn"});
  CHECK(SplitList(",,").empty());
  CHECK(SplitList("").empty());
}

TEST_CASE("ParseInteger accepts decimal, 0x hex and a minus sign, nothing else", "[settings][text]") {
  CHECK(ParseInteger("10") == 10);
  CHECK(ParseInteger(" 10 ") == 10);
  CHECK(ParseInteger("0x1F") == 31);
  CHECK(ParseInteger("0X1f") == 31);
  CHECK(ParseInteger("-5") == -5);
  CHECK(ParseInteger("-0x10") == -16);
  CHECK(ParseInteger("9223372036854775807") == INT64_MAX);
  CHECK(ParseInteger("-9223372036854775808") == INT64_MIN);
  CHECK_FALSE(ParseInteger("9223372036854775808"));
  CHECK_FALSE(ParseInteger(""));
  CHECK_FALSE(ParseInteger("abc"));
  CHECK_FALSE(ParseInteger("12abc"));
  CHECK_FALSE(ParseInteger("0x"));
  CHECK_FALSE(ParseInteger("0xZ"));
  CHECK_FALSE(ParseInteger("+5"));
  CHECK_FALSE(ParseInteger("--5"));
  CHECK_FALSE(ParseInteger("1.5"));
}

TEST_CASE("ParseBool accepts true/false, on/off in any case, and integers", "[settings][text]") {
  CHECK(ParseBool("true") == true);
  CHECK(ParseBool("TRUE") == true);
  CHECK(ParseBool("False") == false);
  CHECK(ParseBool("on") == true);
  CHECK(ParseBool("OFF") == false);
  CHECK(ParseBool("1") == true);
  CHECK(ParseBool("0") == false);
  CHECK(ParseBool("42") == true);
  CHECK(ParseBool("0x0") == false);
  CHECK(ParseBool("0x2") == true);
  CHECK_FALSE(ParseBool("yes"));
  CHECK_FALSE(ParseBool(""));
  CHECK_FALSE(ParseBool("truee"));
}
