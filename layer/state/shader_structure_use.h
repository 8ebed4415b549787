#pragma once
// Which acceleration-structure descriptors a shader module reads (issue 29: top levels traced unbuilt). A pure scan
// of the module's SPIR-V, made once at vkCreateShaderModule (or pipeline creation, for code given inline): the
// descriptor bindings of type OpTypeAccelerationStructureKHR (alone or in arrays) that a function of the module
// loads or indexes, and whether the module traces rays (OpTraceRayKHR) or initializes ray queries
// (OpRayQueryInitializeKHR).
//
// "Statically used" is approximated from below: a binding counts only when an instruction of a function body names
// its variable (OpLoad, an access chain, a copy, a call argument). A binding the scan misses is not checked (a missed
// report, never a false one). Structures reached from an address inside the shader (OpConvertUToAccelerationStructure
// KHR) cannot be seen at all: the scan notes that the module converts addresses, and nothing is checked for them.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace asval {

struct SetBinding {
  uint32_t set = 0;
  uint32_t binding = 0;
  friend bool operator==(const SetBinding& a, const SetBinding& b) { return a.set == b.set && a.binding == b.binding; }
  friend bool operator<(const SetBinding& a, const SetBinding& b) {
    return a.set != b.set ? a.set < b.set : a.binding < b.binding;
  }
};

struct ShaderStructureUse {
  std::vector<SetBinding> bindings;  // sorted, unique
  bool traces = false;               // OpTraceRayKHR
  bool ray_queries = false;          // OpRayQueryInitializeKHR
  bool converts_addresses = false;   // OpConvertUToAccelerationStructureKHR
  bool uses_structures() const { return !bindings.empty(); }
  // Adds another module's (a pipeline's stages).
  void Merge(const ShaderStructureUse& other);
};

// Scans `word_count` words of SPIR-V. nullopt when the code is not SPIR-V the scan can walk (bad magic number, an
// instruction running past the end, a zero word count): the caller treats the module as unknown.
std::optional<ShaderStructureUse> ScanShaderStructureUse(const uint32_t* code, std::size_t word_count);

}  // namespace asval
