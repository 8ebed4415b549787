// Family traces (issue 29): the SPIR-V scan of the structure bindings a shader uses, and the descriptor sets'
// structures as writes, copies, templates, allocations and pool resets leave them (pure logic, no driver).
#include <catch2/catch_test_macros.hpp>
#include <vector>

#include "ray_bindings.h"
#include "ray_query.comp.h"
#include "shader_structure_use.h"
#include "structure_array.comp.h"
#include "trace_ray.rgen.h"
#include "unused_structure.comp.h"
#include "write_value.comp.h"

namespace asval {
namespace {

template <std::size_t N>
std::optional<ShaderStructureUse> Scan(const uint32_t (&code)[N]) {
  return ScanShaderStructureUse(code, N);
}

TEST_CASE("traces unit: the scan finds the structure bindings a shader reads, and which instructions read them") {
  const std::optional<ShaderStructureUse> query = Scan(kRayQueryComp);
  REQUIRE(query);
  CHECK(query->bindings == std::vector<SetBinding>{{0, 0}});
  CHECK(query->ray_queries);
  CHECK_FALSE(query->traces);

  const std::optional<ShaderStructureUse> trace = Scan(kTraceRayRgen);
  REQUIRE(trace);
  CHECK(trace->bindings == std::vector<SetBinding>{{0, 0}});
  CHECK(trace->traces);
  CHECK_FALSE(trace->ray_queries);

  const std::optional<ShaderStructureUse> arrays = Scan(kStructureArrayComp);
  REQUIRE(arrays);
  CHECK(arrays->bindings == std::vector<SetBinding>{{0, 1}, {2, 5}});  // sorted

  // Declared but read by no function; no structure at all.
  const std::optional<ShaderStructureUse> unused = Scan(kUnusedStructureComp);
  REQUIRE(unused);
  CHECK(unused->bindings.empty());
  const std::optional<ShaderStructureUse> none = Scan(kWriteValueComp);
  REQUIRE(none);
  CHECK_FALSE(none->uses_structures());
}

TEST_CASE("traces unit: code the scan cannot walk is unknown, never read past its end") {
  CHECK_FALSE(ScanShaderStructureUse(nullptr, 0));
  const uint32_t not_spirv[6] = {0x12345678, 0, 0, 0, 0, 0};
  CHECK_FALSE(ScanShaderStructureUse(not_spirv, 6));
  std::vector<uint32_t> cut(std::begin(kRayQueryComp), std::end(kRayQueryComp));
  cut.back() = (0xffffu << 16) | 61;  // an OpLoad claiming 65535 words
  CHECK_FALSE(ScanShaderStructureUse(cut.data(), cut.size()));
  std::vector<uint32_t> zero(std::begin(kRayQueryComp), std::end(kRayQueryComp));
  zero[5] = 0;  // an instruction of no words
  CHECK_FALSE(ScanShaderStructureUse(zero.data(), zero.size()));
}

VkAccelerationStructureKHR Structure(uint64_t n) { return reinterpret_cast<VkAccelerationStructureKHR>(n); }
VkDescriptorSet Set(uint64_t n) { return reinterpret_cast<VkDescriptorSet>(n); }

// The structures in a set's binding, as (handle, serial) values; "unknown" and "not written" as empty with the lookup.
std::pair<SetLookup, std::vector<uint64_t>> In(const RayBindings& b, VkDescriptorSet set, uint32_t binding) {
  std::vector<uint64_t> out;
  const SetLookup found = b.ForEachIn(set, binding, [&](const DescribedStructure& d) {
    out.push_back(reinterpret_cast<uint64_t>(d.as));
    out.push_back(d.serial);
  });
  return {found, out};
}

struct Layouts {
  RayBindings bindings;
  const VkDescriptorSetLayout layout = reinterpret_cast<VkDescriptorSetLayout>(uint64_t{0x10});
  const VkDescriptorPool pool = reinterpret_cast<VkDescriptorPool>(uint64_t{0x20});
  Layouts() {
    // binding 0: two structures; binding 1: a storage buffer; binding 2: one structure.
    const VkDescriptorSetLayoutBinding b[3] = {{0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 2, 0, nullptr},
                                               {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, 0, nullptr},
                                               {2, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, 0, nullptr}};
    VkDescriptorSetLayoutCreateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    info.bindingCount = 3;
    info.pBindings = b;
    bindings.AddLayout(info, layout);
  }
  void Allocate(VkDescriptorSet set) {
    VkDescriptorSetAllocateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    info.descriptorPool = pool;
    info.descriptorSetCount = 1;
    info.pSetLayouts = &layout;
    bindings.Allocate(info, &set);
  }
  void Write(VkDescriptorSet set, uint32_t binding, uint32_t element, std::vector<VkAccelerationStructureKHR> as) {
    VkWriteDescriptorSetAccelerationStructureKHR chain{
        VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
    chain.accelerationStructureCount = static_cast<uint32_t>(as.size());
    chain.pAccelerationStructures = as.data();
    VkWriteDescriptorSet write{
        VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,       &chain, set, binding, element, static_cast<uint32_t>(as.size()),
        VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR};
    bindings.Update(1, &write, 0, nullptr,
                    [](VkAccelerationStructureKHR s) { return reinterpret_cast<uint64_t>(s) + 100; });
  }
};

TEST_CASE("traces unit: descriptor sets hold the structures written, copied and allocated over") {
  Layouts l;
  const VkDescriptorSet a = Set(0xa), b = Set(0xb);
  l.Allocate(a);
  l.Allocate(b);
  CHECK(In(l.bindings, a, 0).first == SetLookup::kNotWritten);
  l.Write(a, 0, 0, {Structure(1), Structure(2)});
  CHECK(In(l.bindings, a, 0) == std::make_pair(SetLookup::kFound, std::vector<uint64_t>{1, 101, 2, 102}));
  l.Write(a, 0, 1, {Structure(3)});  // one element rewritten
  CHECK(In(l.bindings, a, 0).second == std::vector<uint64_t>{1, 101, 3, 103});

  VkCopyDescriptorSet copy{VK_STRUCTURE_TYPE_COPY_DESCRIPTOR_SET, nullptr, a, 0, 1, b, 2, 0, 1};
  l.bindings.Update(0, nullptr, 1, &copy, [](VkAccelerationStructureKHR) { return uint64_t{0}; });
  CHECK(In(l.bindings, b, 2).second == std::vector<uint64_t>{3, 103});

  // Past the binding's end the write continues into the next binding: the set becomes unknown.
  l.Write(b, 2, 0, {Structure(4), Structure(5)});
  CHECK(In(l.bindings, b, 2).first == SetLookup::kUnknown);

  // A handle allocated again is a new set; a pool reset forgets its sets.
  l.Allocate(b);
  CHECK(In(l.bindings, b, 2).first == SetLookup::kNotWritten);
  l.bindings.ResetPool(l.pool);
  CHECK(In(l.bindings, a, 0).first == SetLookup::kNotWritten);
  CHECK(l.bindings.set_count() == 0);
}

TEST_CASE("traces unit: templates write the structures at their offsets; an unknown chain makes the set unknown") {
  Layouts l;
  const VkDescriptorSet a = Set(0xa);
  l.Allocate(a);
  const VkDescriptorUpdateTemplateEntry entry{0, 0, 2, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 8, 16};
  VkDescriptorUpdateTemplateCreateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_UPDATE_TEMPLATE_CREATE_INFO};
  info.descriptorUpdateEntryCount = 1;
  info.pDescriptorUpdateEntries = &entry;
  info.templateType = VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET;
  const auto update_template = reinterpret_cast<VkDescriptorUpdateTemplate>(uint64_t{0x30});
  l.bindings.AddTemplate(info, update_template);
  uint64_t data[5] = {0, 7, 0, 9, 0};  // handles at bytes 8 and 24
  l.bindings.UpdateWithTemplate(a, update_template, data, [](VkAccelerationStructureKHR) { return uint64_t{1}; });
  CHECK(In(l.bindings, a, 0).second == std::vector<uint64_t>{7, 1, 9, 1});

  VkBaseInStructure other{VK_STRUCTURE_TYPE_APPLICATION_INFO, nullptr};  // not a structure write's chain
  VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,       &other, a, 2, 0, 1,
                             VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR};
  l.bindings.Update(1, &write, 0, nullptr, [](VkAccelerationStructureKHR) { return uint64_t{1}; });
  CHECK(In(l.bindings, a, 0).first == SetLookup::kUnknown);
}

}  // namespace
}  // namespace asval
