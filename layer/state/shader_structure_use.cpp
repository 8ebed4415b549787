#include "shader_structure_use.h"

#include <algorithm>
#include <unordered_map>
#include <unordered_set>

namespace asval {

namespace {

// SPIR-V (the unified specification's numbers).
constexpr uint32_t kMagic = 0x07230203;
constexpr uint32_t kHeaderWords = 5;
enum Op : uint32_t {
  kOpDecorate = 71,
  kOpTypeArray = 28,
  kOpTypeRuntimeArray = 29,
  kOpTypePointer = 32,
  kOpFunction = 54,
  kOpFunctionEnd = 56,
  kOpFunctionCall = 57,
  kOpVariable = 59,
  kOpLoad = 61,
  kOpCopyMemory = 63,
  kOpAccessChain = 65,
  kOpInBoundsAccessChain = 66,
  kOpPtrAccessChain = 67,
  kOpInBoundsPtrAccessChain = 70,
  kOpCopyObject = 83,
  kOpTraceRayKHR = 4445,
  kOpConvertUToAccelerationStructureKHR = 4447,
  kOpRayQueryInitializeKHR = 4473,
  kOpTraceNV = 5337,
  kOpTypeAccelerationStructureKHR = 5341,  // also OpTypeAccelerationStructureNV
};
constexpr uint32_t kDecorationBinding = 33;
constexpr uint32_t kDecorationDescriptorSet = 34;

struct Decorations {
  std::optional<uint32_t> set, binding;
};

}  // namespace

void ShaderStructureUse::Merge(const ShaderStructureUse& other) {
  for (const SetBinding& b : other.bindings) {
    const auto at = std::lower_bound(bindings.begin(), bindings.end(), b);
    if (at == bindings.end() || !(*at == b)) bindings.insert(at, b);
  }
  traces |= other.traces;
  ray_queries |= other.ray_queries;
  converts_addresses |= other.converts_addresses;
}

std::optional<ShaderStructureUse> ScanShaderStructureUse(const uint32_t* code, std::size_t word_count) {
  if (!code || word_count < kHeaderWords || code[0] != kMagic) return std::nullopt;
  ShaderStructureUse use;
  std::unordered_set<uint32_t> structure_types;       // the structure type, and arrays of it
  std::unordered_map<uint32_t, uint32_t> pointer_to;  // pointer type -> pointee
  std::vector<uint32_t> variables;                    // variables of a pointer type, in order
  std::unordered_map<uint32_t, uint32_t> variable_type;
  std::unordered_map<uint32_t, Decorations> decorations;
  std::unordered_set<uint32_t> named_in_functions;  // pointer operands of function-body instructions
  bool in_function = false;

  for (std::size_t at = kHeaderWords; at < word_count;) {
    const uint32_t count = code[at] >> 16;
    const uint32_t opcode = code[at] & 0xffffu;
    if (count == 0 || at + count > word_count) return std::nullopt;
    const uint32_t* w = code + at;
    switch (opcode) {
      case kOpDecorate:
        if (count >= 4 && (w[2] == kDecorationBinding || w[2] == kDecorationDescriptorSet)) {
          Decorations& d = decorations[w[1]];
          (w[2] == kDecorationBinding ? d.binding : d.set) = w[3];
        }
        break;
      case kOpTypeAccelerationStructureKHR:
        if (count >= 2) structure_types.insert(w[1]);
        break;
      case kOpTypeArray:
      case kOpTypeRuntimeArray:
        if (count >= 3 && structure_types.count(w[2])) structure_types.insert(w[1]);
        break;
      case kOpTypePointer:
        if (count >= 4) pointer_to[w[1]] = w[3];
        break;
      case kOpVariable:
        if (!in_function && count >= 4) {
          variables.push_back(w[2]);
          variable_type[w[2]] = w[1];
        }
        break;
      case kOpFunction:
        in_function = true;
        break;
      case kOpFunctionEnd:
        in_function = false;
        break;
      case kOpTraceRayKHR:
      case kOpTraceNV:
        use.traces = true;
        break;
      case kOpRayQueryInitializeKHR:
        use.ray_queries = true;
        break;
      case kOpConvertUToAccelerationStructureKHR:
        use.converts_addresses = true;
        break;
      default:
        break;
    }
    if (in_function) {
      switch (opcode) {
        case kOpLoad:
        case kOpAccessChain:
        case kOpInBoundsAccessChain:
        case kOpPtrAccessChain:
        case kOpInBoundsPtrAccessChain:
        case kOpCopyObject:
          if (count >= 4) named_in_functions.insert(w[3]);
          break;
        case kOpCopyMemory:
          if (count >= 3) named_in_functions.insert(w[2]);
          break;
        case kOpFunctionCall:
          for (uint32_t i = 4; i < count; ++i) named_in_functions.insert(w[i]);
          break;
        default:
          break;
      }
    }
    at += count;
  }

  for (uint32_t variable : variables) {
    const auto pointer = pointer_to.find(variable_type[variable]);
    if (pointer == pointer_to.end() || !structure_types.count(pointer->second)) continue;
    if (!named_in_functions.count(variable)) continue;
    const auto d = decorations.find(variable);
    if (d == decorations.end() || !d->second.set || !d->second.binding) continue;
    use.bindings.push_back(SetBinding{*d->second.set, *d->second.binding});
  }
  std::sort(use.bindings.begin(), use.bindings.end());
  use.bindings.erase(std::unique(use.bindings.begin(), use.bindings.end()), use.bindings.end());
  return use;
}

}  // namespace asval
