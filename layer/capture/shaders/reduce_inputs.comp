#version 460
// Execution-time capture, reduced on the device (issue 12, setting capture_method): instead of copying a build's
// vertices, AABBs or instance records to the host, the layer's dispatch reads them where the build reads them
// and writes only what the rules need, as the reference builder defines it (layer/builder, classify.h):
//   triangles  per primitive: active (no vertex's X is NaN), undefined input (a NaN Y or Z with X not NaN, active
//              primitives only), unreadable (an index that names a vertex above maxVertex: never read); per 64
//              triangles the hash of their index bytes (builder::HashIndexBlock, layer/builder's index_hash.h, bit
//              for bit: the host combines one hash per block); and the transform as it is;
//   AABBs      per primitive: active (minX not NaN), undefined input (another NaN with minX not NaN);
//   instances  per record: its accelerationStructureReference, active (a reference other than 0), and whether
//              its transform has a NaN or infinite element (per 32 records, the first such one's element too);
//              per 64 records, each distinct reference other than 0 once, with the first record holding it;
//   arrays of instance pointers (job kind 3, the second stage of their capture: where they point is known only
//              now): the pointers as they are, then per pointer the 64-byte record it names, copied, when it is
//              not 0 and aligned to 16 bytes (FollowedInstancePointer, capture_log.h: the build reads those 64
//              bytes itself; a misaligned one is pInfos-03717 and never chased), else zeros.
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
  uint kind;          // 0 triangles, 1 AABBs, 2 instances, 3 arrays of instance pointers (gathered); | 256: indirect
  uint count;         // primitives (indirect: the most, ppMaxPrimitiveCounts)
  uint stride;        // vertex, AABB or instance stride in bytes
  uint format;        // triangles: x_kind | components << 8 | index_bytes << 16 (below)
  uint first_vertex;  // indexed triangles: added to each index
  uint max_vertex;    // indexed triangles: the highest vertex that may be read
  uvec2 data;         // vertices (not indexed: the first one read), AABBs or instance records
  uvec2 indices;      // indexed triangles: the first index read
  uvec2 out_addr;     // results
  uvec2 transform;    // triangles: the transform (0: none, or not captured)
  uvec2 range;        // indirect: the geometry's VkAccelerationStructureBuildRangeInfoKHR, where the build reads it
};
// Job::format: x_kind 0 no NaN (normalized formats), 1 float32, 2 float16; components 2 or 3 (Y and Z tested for
// the undefined-input bit); index_bytes 0 (not indexed), 1, 2 or 4.
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

// Indexed triangles: this group's 64 triangles' index bytes, read once by the whole group in aligned words (the
// block's first byte is byte g_index_skew of the first word): each invocation takes its triangle's indices from
// here, and the hash lanes walk them here rather than in device memory (a lane's steps are a chain, each of which
// would otherwise wait for a load).
shared uint s_index_words[194];  // 192 * 4 index bytes, one word of skew, one of spill
uint g_index_skew;  // the same in every invocation of the group
// The job, read once per group by its first invocation (it lies in host-visible memory: one read, not 64).
shared Job s_job;

// `bytes` (1 to 4) little-endian bytes at byte `offset` of the staged index block.
uint StagedBytes(uint offset, uint bytes) {
  const uint at = g_index_skew + offset;
  const uint misalign = at & 3u;
  uint value = s_index_words[at >> 2] >> (8u * misalign);
  if (misalign + bytes > 4u) value |= s_index_words[(at >> 2) + 1u] << (32u - 8u * misalign);
  return bytes == 4u ? value : value & ((1u << (8u * bytes)) - 1u);
}

// 64-bit words as uvec2(low, high): what the index hash (index_hash.cpp) computes, without shaderInt64.
uvec2 Mul64(uvec2 a, uvec2 b) {
  uint hi, lo;
  umulExtended(a.x, b.x, hi, lo);
  return uvec2(lo, hi + a.x * b.y + a.y * b.x);
}
uvec2 Rotl64(uvec2 x, uint r) {  // 0 < r < 64
  if (r >= 32u) { x = x.yx; r -= 32u; }
  return r == 0u ? x : uvec2((x.x << r) | (x.y >> (32u - r)), (x.y << r) | (x.x >> (32u - r)));
}
uvec2 Fmix64(uvec2 k) {  // murmur3's finaliser: k ^= k >> 33 is k.x ^= k.y >> 1
  k.x ^= k.y >> 1u;
  k = Mul64(k, uvec2(0xED558CCDu, 0xFF51AFD7u));
  k.x ^= k.y >> 1u;
  k = Mul64(k, uvec2(0x1A85EC53u, 0xC4CEB9FEu));
  k.x ^= k.y >> 1u;
  return k;
}
const uvec2 kPrime[4] = uvec2[4](uvec2(0x85EBCA87u, 0x9E3779B1u), uvec2(0x27D4EB4Fu, 0xC2B2AE3Du),
                                 uvec2(0x9E3779F9u, 0x165667B1u), uvec2(0x6659FD93u, 0xD6E8FEB8u));
// Lane `lane` of the hash of the staged block's `bytes` index bytes seeded with the element size: its word of each
// whole 32-byte step, then its word of the tail (zero-padded), if the tail reaches it.
uvec2 IndexHashLane(uint bytes, uint seed, uint lane) {
  const uvec2 s = uvec2(seed, 0u);
  uvec2 h;
  if (lane == 0u) h = s ^ kPrime[0];
  else if (lane == 1u) h = Add64(s, kPrime[1].x, kPrime[1].y);
  else if (lane == 2u) h = Rotl64(s, 17u) ^ kPrime[2];
  else h = ~s ^ kPrime[3];
  const uint whole = bytes & ~31u;
  for (uint step = 0u; step < whole; step += 32u) {
    const uint word = step + 8u * lane;
    const uvec2 w = uvec2(StagedBytes(word, 4u), StagedBytes(word + 4u, 4u));
    h = Mul64(Rotl64(h ^ w, 29u), kPrime[lane]);
  }
  const uint tail = bytes - whole;
  if (8u * lane < tail) {
    const uint left = tail - 8u * lane;
    const uint word = whole + 8u * lane;
    const uint high = left > 4u ? StagedBytes(word + 4u, min(4u, left - 4u)) : 0u;
    const uvec2 w = uvec2(StagedBytes(word, min(4u, left)), high);
    h = Mul64(Rotl64(h ^ w, 29u), kPrime[lane]);
  }
  return h;
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
// Indexed triangles: the four lanes of the index hash of this group's 64 triangles.
shared uvec2 s_lanes[4];

// The job as the group uses it. An indirect build's geometry (issue 28): where its bytes start and how many
// primitives it has are in its range info, on the device, read here where the build read it (after the build:
// nothing wrote it in between). The addresses of the job are then those of a range of offset 0, and its count the
// most the build may read; the results are laid out for the range's own count (the host reads that count from the
// range info it copied).
Job ReadJob(Job job) {
  if ((job.kind & 256u) != 0u) {
    const uint count = LoadBytes(job.range, 4u);
    const uint primitive_offset = LoadBytes(Add64(job.range, 4u, 0u), 4u);
    const uint first_vertex = LoadBytes(Add64(job.range, 8u, 0u), 4u);
    const uint transform_offset = LoadBytes(Add64(job.range, 12u, 0u), 4u);
    job.count = min(job.count, count);
    job.kind &= 255u;
    if (job.kind == 0u && ((job.format >> 16) & 255u) != 0u) {  // indexed: indices from the offset
      job.indices = Add64(job.indices, primitive_offset, 0u);
      job.first_vertex = first_vertex;
    } else if (job.kind == 0u) {  // not indexed: vertices from the offset, firstVertex of them on
      job.data = AddProduct(Add64(job.data, primitive_offset, 0u), first_vertex, job.stride);
    } else {
      job.data = Add64(job.data, primitive_offset, 0u);
    }
    if (job.transform != uvec2(0u)) job.transform = Add64(job.transform, transform_offset, 0u);
  }
  return job;
}

void main() {
  if (gl_LocalInvocationID.x == 0u) {
    const uint job_index = gl_WorkGroupID.y + 32768u * gl_WorkGroupID.z;
    const uvec2 slab = Addresses(uvec2(kTableLo, kTableHi)).a[job_index >> 16];
    s_job = ReadJob(JobRef(AddProduct(slab, job_index & 0xffffu, 64u)).job);
  }
  barrier();
  const Job job = s_job;
  const uint x_kind = job.format & 255u;
  const uint components = (job.format >> 8) & 255u;
  const uint index_bytes = (job.format >> 16) & 255u;
  const uint words = (job.count + 31u) / 32u;
  const uint local = gl_LocalInvocationID.x;
  const uint stride_x = gl_NumWorkGroups.x * 64u;
  // Triangles: after the bit arrays, indexed ones the index hash's blocks (16 bytes per 64 triangles, written in
  // the loop below), then the transform, copied.
  const uint index_total = 3u * job.count * index_bytes;
  const uint hash_blocks = index_bytes != 0u ? (job.count + 63u) / 64u : 0u;
  const uvec2 out_hashes = AddProduct(job.out_addr, 3u * words, 4u);
  if (job.kind == 0u && gl_WorkGroupID.x == 0u && local < 12u && job.transform != uvec2(0u)) {
    const uvec2 out_transform = AddProduct(out_hashes, hash_blocks, 16u);
    OutWords(AddProduct(out_transform, local, 4u)).w[0] = LoadBytes(AddProduct(job.transform, local, 4u), 4u);
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
    // Indexed triangles: these 64 triangles' index bytes, staged (their first byte at g_index_skew).
    const uint block_first = 3u * group_first * index_bytes;
    const uint block_bytes = min(192u * index_bytes, index_total - min(block_first, index_total));
    if (job.kind == 0u && index_bytes != 0u) {
      const uvec2 first = Add64(job.indices, block_first, 0u);
      g_index_skew = first.x & 3u;
      Words block = Words(uvec2(first.x & ~3u, first.y));
      for (uint w = local; w < (g_index_skew + block_bytes + 3u) / 4u; w += 64u) s_index_words[w] = block.w[w];
    }
    barrier();
    const uint t = group_first + local;
    bool is_active = false, undefined_input = false, unreadable = false;
    if (t < job.count) {
      if (job.kind == 0u) {
        uint v[3];
        for (uint k = 0u; k < 3u; ++k) {
          if (index_bytes == 0u) {
            v[k] = 3u * t + k;
          } else {
            const uint index = StagedBytes((3u * local + k) * index_bytes, index_bytes);
            uint carry;
            v[k] = uaddCarry(index, job.first_vertex, carry);
            unreadable = unreadable || carry != 0u || v[k] > job.max_vertex;
          }
        }
        bool x_nan = false, yz_nan = false;
        if (!unreadable && x_kind != 0u) {
          for (uint k = 0u; k < 3u; ++k) {
            const uvec2 p = AddProduct(job.data, v[k], job.stride);
            if (x_kind == 1u) {
              x_nan = x_nan || NaN32(LoadBytes(p, 4u));
              yz_nan = yz_nan || NaN32(LoadBytes(Add64(p, 4u, 0u), 4u));
              if (components > 2u) yz_nan = yz_nan || NaN32(LoadBytes(Add64(p, 8u, 0u), 4u));
            } else {
              x_nan = x_nan || NaN16(LoadBytes(p, 2u));
              yz_nan = yz_nan || NaN16(LoadBytes(Add64(p, 2u, 0u), 2u));
              if (components > 2u) yz_nan = yz_nan || NaN16(LoadBytes(Add64(p, 4u, 0u), 2u));
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
    // Indexed triangles: these 64 triangles' indices hashed, one lane per invocation (each lane is a chain).
    if (job.kind == 0u && index_bytes != 0u && local < 4u) {
      s_lanes[local] = IndexHashLane(block_bytes, index_bytes, local);
    }
    barrier();
    if (job.kind == 0u && index_bytes != 0u && local == 0u) {  // IndexHasher::Finish
      const uvec2 total = uvec2(block_bytes, 0u);
      const uvec2 a = Fmix64(s_lanes[0] ^ Rotl64(s_lanes[2], 23u) ^ total);
      const uvec2 b = Fmix64(s_lanes[1] ^ Rotl64(s_lanes[3], 41u) ^ Mul64(total, kPrime[0]));
      const uvec2 lo = Fmix64(Add64(a, b.x, b.y));
      const uvec2 hi = Fmix64(b ^ Rotl64(a, 32u));
      OutWords hash_out = OutWords(AddProduct(out_hashes, group_first / 64u, 16u));
      hash_out.w[0] = lo.x;
      hash_out.w[1] = lo.y;
      hash_out.w[2] = hi.x;
      hash_out.w[3] = hi.y;
    }
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
