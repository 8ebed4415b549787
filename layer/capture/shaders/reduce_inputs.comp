#version 460
// Execution-time capture, reduced on the device (issue 12, setting capture_method): instead of copying a build's
// vertices, AABBs or instance records to the host, the layer's dispatch reads them where the build reads them
// and writes only what the rules need, as the reference builder defines it (layer/builder, classify.h):
//   triangles  per primitive: active (no vertex's X is NaN), undefined input (a NaN Y or Z with X not NaN, active
//              primitives only), unreadable (an index that names a vertex above maxVertex: never read); and the
//              index bytes and the transform as they are (the host hashes the indices);
//   AABBs      per primitive: active (minX not NaN), undefined input (another NaN with minX not NaN);
//   instances  per record: its accelerationStructureReference, active (a reference other than 0), and whether
//              its transform has a NaN or infinite element (per 32 records, the first such one's element too);
//              per 64 records, each distinct reference other than 0 once, with the first record holding it;
//   arrays of instance pointers (job kind 3, the second stage of their capture: where they point is known only
//              now): the pointers as they are, then per pointer the 64-byte record it names, copied, when it is
//              not 0 and aligned to 16 bytes (FollowedInstancePointer, capture_log.h: the build reads those 64
//              bytes right after this dispatch; a misaligned one is pInfos-03717 and never chased), else zeros.
// Bit arrays hold one bit per primitive in 32-bit words (bit t % 32 of word t / 32), zero past the count. The
// layout of the results is ReducedGeometry's (layer/state/capture_log.h).
//
// No descriptor set, no push constant: the app's own stay as they are. The specialization constant is the
// device address of the capture pool's slab table (one device address per slab); each row of Y groups is one
// job: job = group Y + 32768 * group Z (vkCmdDispatchBase), whose slab is job >> 16 and whose parameters lie
// 64 * (job & 0xffff) bytes into it. The X groups walk the primitives (a grid-stride loop beyond 65535 groups).
// Addresses are uvec2 (no shaderInt64 needed); every load is a 32-bit load of an aligned word that holds at least
// one byte of what is read, so it never leaves a page the build reads itself.
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require

layout(local_size_x = 64) in;

layout(constant_id = 0) const uint kTableLo = 0u;
layout(constant_id = 1) const uint kTableHi = 0u;

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer Words { uint w[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer OutWords { uint w[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer Addresses { uvec2 a[]; };

// Must match ReduceJob (layer/capture/capture_reducer.h).
struct Job {
  uint kind;          // 0 triangles, 1 AABBs, 2 instances, 3 arrays of instance pointers (gathered)
  uint count;         // primitives
  uint stride;        // vertex, AABB or instance stride in bytes
  uint x_kind;        // triangles: 0 no NaN (normalized formats), 1 float32, 2 float16
  uint components;    // triangles: 2 or 3 (Y and Z tested for the undefined-input bit)
  uint index_bytes;   // triangles: 0 (not indexed), 1, 2 or 4
  uint first_vertex;  // indexed triangles: added to each index
  uint max_vertex;    // indexed triangles: the highest vertex that may be read
  uvec2 data;         // vertices (not indexed: the first one read), AABBs or instance records
  uvec2 indices;      // indexed triangles: the first index read
  uvec2 out_addr;     // results
  uvec2 transform;    // triangles: the transform (0: none, or not captured)
};
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer JobRef { Job job; };

uvec2 Add64(uvec2 a, uint lo, uint hi) {
  uint carry;
  const uint l = uaddCarry(a.x, lo, carry);
  return uvec2(l, a.y + hi + carry);
}
uvec2 AddProduct(uvec2 a, uint x, uint y) {
  uint hi, lo;
  umulExtended(x, y, hi, lo);
  return Add64(a, lo, hi);
}

// `bytes` (1 to 4) little-endian bytes at any byte address.
uint LoadBytes(uvec2 address, uint bytes) {
  const uint misalign = address.x & 3u;
  const uvec2 base = uvec2(address.x & ~3u, address.y);
  uint value = Words(base).w[0] >> (8u * misalign);
  if (misalign + bytes > 4u) value |= Words(base).w[1] << (32u - 8u * misalign);
  return bytes == 4u ? value : value & ((1u << (8u * bytes)) - 1u);
}

bool NaN32(uint bits) { return (bits & 0x7fffffffu) > 0x7f800000u; }
bool NaN16(uint bits) { return (bits & 0x7fffu) > 0x7c00u; }
bool NonFinite32(uint bits) { return (bits & 0x7f800000u) == 0x7f800000u; }

// This group's 64 primitives: three bit arrays of two words (instances: the third holds the first non-finite
// transform's lane and element per word instead).
shared uint s_bits[3][2];
// Instances: this group's references (0: none, or inactive), and how many distinct ones it found.
shared uvec2 s_refs[64];
shared uint s_distinct;

void main() {
  const uint job_index = gl_WorkGroupID.y + 32768u * gl_WorkGroupID.z;
  const uvec2 slab = Addresses(uvec2(kTableLo, kTableHi)).a[job_index >> 16];
  const Job job = JobRef(AddProduct(slab, job_index & 0xffffu, 64u)).job;
  const uint words = (job.count + 31u) / 32u;
  const uint local = gl_LocalInvocationID.x;
  const uint stride_x = gl_NumWorkGroups.x * 64u;
  // Triangles: the index bytes (rounded up to words) and the transform, copied after the bit arrays.
  if (job.kind == 0u) {
    const uvec2 out_indices = AddProduct(job.out_addr, 3u * words, 4u);
    const uint index_total = 3u * job.count * job.index_bytes;
    for (uint w = gl_WorkGroupID.x * 64u + local; 4u * w < index_total; w += stride_x) {
      OutWords(AddProduct(out_indices, w, 4u)).w[0] =
          LoadBytes(AddProduct(job.indices, w, 4u), min(4u, index_total - 4u * w));
    }
    if (gl_WorkGroupID.x == 0u && local < 12u && job.transform != uvec2(0u)) {
      const uvec2 out_transform = AddProduct(out_indices, (index_total + 3u) / 4u, 4u);
      OutWords(AddProduct(out_transform, local, 4u)).w[0] = LoadBytes(AddProduct(job.transform, local, 4u), 4u);
    }
  }
  // Arrays of instance pointers: gathered, no bits (the host classifies the records as it does copied ones). The
  // job is the group's, so the whole group returns here, before any barrier.
  if (job.kind == 3u) {
    const uvec2 out_records = AddProduct(job.out_addr, job.count, 8u);
    for (uint t = gl_WorkGroupID.x * 64u + local; t < job.count; t += stride_x) {
      const uvec2 at = AddProduct(job.data, t, 8u);
      const uvec2 pointer = uvec2(LoadBytes(at, 4u), LoadBytes(Add64(at, 4u, 0u), 4u));
      OutWords pointer_out = OutWords(AddProduct(job.out_addr, t, 8u));
      pointer_out.w[0] = pointer.x;
      pointer_out.w[1] = pointer.y;
      const uvec2 record_out = AddProduct(out_records, t, 64u);
      // A branch, not a select: the load must not be made for a pointer that is not followed.
      if (pointer != uvec2(0u) && (pointer.x & 15u) == 0u) {
        for (uint k = 0u; k < 16u; ++k) OutWords(AddProduct(record_out, k, 4u)).w[0] = Words(pointer).w[k];
      } else {
        for (uint k = 0u; k < 16u; ++k) OutWords(AddProduct(record_out, k, 4u)).w[0] = 0u;
      }
    }
    return;
  }
  // Uniform over the group: every invocation takes part in each round's barriers.
  for (uint group_first = gl_WorkGroupID.x * 64u; group_first < job.count; group_first += stride_x) {
    if (local < 6u) s_bits[local / 2u][local % 2u] = (job.kind == 2u && local >= 4u) ? 0xffffffffu : 0u;
    if (local == 0u) s_distinct = 0u;
    s_refs[local] = uvec2(0u);
    barrier();
    const uint t = group_first + local;
    bool is_active = false, undefined_input = false, unreadable = false;
    if (t < job.count) {
      if (job.kind == 0u) {
        uint v[3];
        for (uint k = 0u; k < 3u; ++k) {
          if (job.index_bytes == 0u) {
            v[k] = 3u * t + k;
          } else {
            const uint index = LoadBytes(AddProduct(job.indices, 3u * t + k, job.index_bytes), job.index_bytes);
            uint carry;
            v[k] = uaddCarry(index, job.first_vertex, carry);
            unreadable = unreadable || carry != 0u || v[k] > job.max_vertex;
          }
        }
        bool x_nan = false, yz_nan = false;
        if (!unreadable && job.x_kind != 0u) {
          for (uint k = 0u; k < 3u; ++k) {
            const uvec2 p = AddProduct(job.data, v[k], job.stride);
            if (job.x_kind == 1u) {
              x_nan = x_nan || NaN32(LoadBytes(p, 4u));
              yz_nan = yz_nan || NaN32(LoadBytes(Add64(p, 4u, 0u), 4u));
              if (job.components > 2u) yz_nan = yz_nan || NaN32(LoadBytes(Add64(p, 8u, 0u), 4u));
            } else {
              x_nan = x_nan || NaN16(LoadBytes(p, 2u));
              yz_nan = yz_nan || NaN16(LoadBytes(Add64(p, 2u, 0u), 2u));
              if (job.components > 2u) yz_nan = yz_nan || NaN16(LoadBytes(Add64(p, 4u, 0u), 2u));
            }
          }
        }
        is_active = unreadable || !x_nan;  // unreadable: recorded active, as the builder does (and then unknown)
        undefined_input = !unreadable && !x_nan && yz_nan;
      } else if (job.kind == 1u) {
        const uvec2 p = AddProduct(job.data, t, job.stride);
        const bool min_x_nan = NaN32(LoadBytes(p, 4u));
        bool other_nan = false;
        for (uint c = 1u; c < 6u; ++c) other_nan = other_nan || NaN32(LoadBytes(Add64(p, 4u * c, 0u), 4u));
        is_active = !min_x_nan;
        undefined_input = !min_x_nan && other_nan;
      } else {
        const uvec2 p = AddProduct(job.data, t, job.stride);
        uint first_element = 12u;  // the first NaN or infinite element of the transform (row * 4 + column)
        for (uint c = 12u; c > 0u; --c) {
          if (NonFinite32(LoadBytes(Add64(p, 4u * (c - 1u), 0u), 4u))) first_element = c - 1u;
        }
        const bool non_finite = first_element < 12u;
        // The group's first such instance per word, with its element: (lane << 4) | element, the least wins.
        if (non_finite) atomicMin(s_bits[2][local / 32u], ((local % 32u) << 4) | first_element);
        const uvec2 reference = uvec2(LoadBytes(Add64(p, 56u, 0u), 4u), LoadBytes(Add64(p, 60u, 0u), 4u));
        OutWords refs = OutWords(AddProduct(job.out_addr, t, 8u));
        refs.w[0] = reference.x;
        refs.w[1] = reference.y;
        is_active = reference != uvec2(0u);  // the spec's inactive instance: a reference of 0
        s_refs[local] = reference;
        undefined_input = non_finite;        // the instances' second bit array: a non-finite transform
      }
      const uint bit = 1u << (local % 32u);
      if (is_active) atomicOr(s_bits[0][local / 32u], bit);
      if (undefined_input) atomicOr(s_bits[1][local / 32u], bit);
      if (unreadable) atomicOr(s_bits[2][local / 32u], bit);
    }
    barrier();
    // Instances: each distinct reference of these 64 records once, with the first record holding it, so that the
    // host looks up a few references per 64 records (the records' own, all of them, stay above for messages).
    const uvec2 summary =
        AddProduct(Add64(AddProduct(job.out_addr, job.count, 8u), 12u * words, 0u), group_first / 64u, 1040u);
    if (job.kind == 2u && s_refs[local] != uvec2(0u)) {
      bool first = true;
      for (uint l = 0u; l < local; ++l) first = first && s_refs[l] != s_refs[local];
      if (first) {
        const uint slot = atomicAdd(s_distinct, 1u);
        OutWords entry = OutWords(AddProduct(Add64(summary, 16u, 0u), slot, 16u));
        entry.w[0] = s_refs[local].x;
        entry.w[1] = s_refs[local].y;
        entry.w[2] = group_first + local;
      }
    }
    barrier();
    if (job.kind == 2u && local == 0u) OutWords(summary).w[0] = s_distinct;
    const uint word = group_first / 32u + local % 2u;
    if (local < 6u && word < words) {
      // Three arrays one after the other: triangles and AABBs active, undefined, unreadable; instances (after
      // their references, 8 bytes each) active, non-finite transform, and per word its first such instance's
      // (lane << 4) | element (all ones: none).
      const uint array = local / 2u;
      const uvec2 arrays = job.kind == 2u ? AddProduct(job.out_addr, job.count, 8u) : job.out_addr;
      OutWords(AddProduct(arrays, array * words + word, 4u)).w[0] = s_bits[array][local % 2u];
    }
    barrier();
  }
}
