// buffer_cycle: what the layers cost per buffer lifetime: vkCreateBuffer, vkGetBufferMemoryRequirements,
// vkBindBufferMemory and vkDestroyBuffer, CYCLES times, into one memory allocation made beforehand. asval keeps a
// shadow of every buffer bound to memory (its range, usage and device address) for the address and aliasing
// rules; this is that upkeep, paid by apps that create and destroy buffers every frame. Only the cycles are
// between the callgrind client requests. Argument: cycles.
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "bench_device.h"
#include "instrument.h"
#include "vkkit.h"

namespace {

int Run(int argc, char** argv) {
  const int cycles = argc > 1 ? std::atoi(argv[1]) : 20000;
  if (cycles < 1) {
    std::fprintf(stderr, "usage: buffer_cycle CYCLES\n");
    return 2;
  }
  overhead::BenchDevice bench;
  vkkit::Device& device = bench.device();
  const VkDevice handle = device.handle();
  // The usage of a build input with a device address: the buffers the layer's address map holds.
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = 64 * 1024;
  info.usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
               VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkBuffer probe = VK_NULL_HANDLE;
  vkkit::Check(vkCreateBuffer(handle, &info, nullptr, &probe), "vkCreateBuffer");
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(handle, probe, &req);
  vkDestroyBuffer(handle, probe, nullptr);
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = device.FindMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  vkkit::Check(vkAllocateMemory(handle, &alloc, nullptr, &memory), "vkAllocateMemory");

  const auto start = std::chrono::steady_clock::now();
  OVERHEAD_START_INSTRUMENTATION;
  for (int i = 0; i < cycles; ++i) {
    VkBuffer buffer = VK_NULL_HANDLE;
    vkkit::Check(vkCreateBuffer(handle, &info, nullptr, &buffer), "vkCreateBuffer");
    // Queried every time, as apps do before binding (and as the Khronos layer expects).
    VkMemoryRequirements cycle_req;
    vkGetBufferMemoryRequirements(handle, buffer, &cycle_req);
    vkkit::Check(vkBindBufferMemory(handle, buffer, memory, 0), "vkBindBufferMemory");
    vkDestroyBuffer(handle, buffer, nullptr);
  }
  OVERHEAD_STOP_INSTRUMENTATION;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  vkFreeMemory(handle, memory, nullptr);
  std::printf("%d buffer cycles (create, requirements, bind, destroy)\n", cycles);
  return bench.Finish(cycles, seconds);
}

}  // namespace

int main(int argc, char** argv) { return overhead::Main("buffer_cycle", Run, argc, argv); }
