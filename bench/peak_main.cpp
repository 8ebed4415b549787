// Peak memory of ONE build in a fresh process: bytes allocated (every allocation counted, touched or not)
// and bytes resident (the kernel's high-water mark), per primitive. A fresh process per figure because a
// long-running one keeps freed memory around that later builds reuse without it showing as new residency.
// Usage: asval_builder_peak SCENE [TRIANGLES=1000000] [sah|lbvh] [THREADS=1]
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "bench_common.h"

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s uniform|sphere|terrain|clustered [triangles] [sah|lbvh] [threads]\n", argv[0]);
        return 64;
    }
    const std::string scene = argv[1];
    const uint32_t n = argc > 2 ? uint32_t(std::strtoul(argv[2], nullptr, 10)) : 1000000;
    asval::builder::BuildOptions o;
    if (argc > 3 && std::strcmp(argv[3], "lbvh") == 0) o.mode = asval::builder::BuildMode::Lbvh;
    o.threads = argc > 4 ? uint32_t(std::strtoul(argv[4], nullptr, 10)) : 1;
    const scenes::Scene& s = bench::CachedScene(scene, n);
    const bench::BuildRun r = bench::RunBuild(s, o);
    std::printf("%s,%u,%s,%u,alloc_peak_B_per_prim=%.1f,resident_peak_B_per_prim=%.1f,sah=%.4f\n", scene.c_str(), n,
                o.mode == asval::builder::BuildMode::Lbvh ? "lbvh" : "sah", o.threads,
                double(r.peakBytes) / n, double(r.peakResidentBytes) / n, r.sah);
    return 0;
}
