#pragma once
// The accuracy corpus: small programs, each one case of what ray-tracing programs do with acceleration
// structures, labelled with the VUIDs a validation layer must report for it (none for a valid program).
// `asval_corpus --list` prints the labels; `asval_corpus CASE` runs one case in this process under whatever
// layers ASVAL_TEST_LAYERS names (run_corpus.py runs each case in its own process, under asval and under the
// Khronos layer, and compares). Cases are written against the Vulkan API only: nothing in them knows asval.
#include <string>
#include <vector>

#include "vkkit.h"

namespace corpus {

using CaseBody = void (*)(vkkit::Device& device);

struct Case {
  const char* name;     // unique, kebab-case
  const char* family;   // the rule family it exercises (asval's families; "patterns" for whole-program patterns)
  const char* pattern;  // what the program does, in one sentence
  std::vector<std::string> expected;  // the VUIDs it must trigger, newest spelling; empty: valid, must stay silent
  CaseBody body;
  // A case that needs what only asval's test driver executes (tests/driver): the features its device enables
  // ("host-commands", "indirect-build", comma-separated); run_corpus.py runs it there. Null: lavapipe.
  const char* test_driver = nullptr;
};

// Every case of the program, in registration order.
std::vector<Case>& Cases();

// The instance the running case's device belongs to, with the corpus messenger attached (for a case that makes a
// device of its own, e.g. without a feature the case is about).
vkkit::Instance& CurrentInstance();

struct Registrar {
  explicit Registrar(Case c) { Cases().push_back(std::move(c)); }
};

}  // namespace corpus

// CORPUS_CASE_ON_TEST_DRIVER(function, "name", "family", "features", "pattern", {"VUID-...", ...}) { body }: a case
// that runs on asval's test driver, its device enabling those features (Case::test_driver).
#define CORPUS_CASE_ON_TEST_DRIVER(function, name, family, features, pattern, ...)                           \
  static void function(vkkit::Device& device);                                                                \
  static const corpus::Registrar function##_registrar({name, family, pattern, __VA_ARGS__, &function, features}); \
  static void function([[maybe_unused]] vkkit::Device& device)

// CORPUS_CASE(function, "name", "family", "pattern", {"VUID-...", ...}) { body using `device` }
#define CORPUS_CASE(function, name, family, pattern, ...)                                          \
  static void function(vkkit::Device& device);                                                       \
  static const corpus::Registrar function##_registrar({name, family, pattern, __VA_ARGS__, &function}); \
  static void function([[maybe_unused]] vkkit::Device& device)
