// host/optics/gradient_volume.cpp — the Sobel gradient RGBA volume (host/optics/gradient_volume.h), rows of z-slices
// spread over host threads.
#include "host/optics/gradient_volume.h"

#include "host/runtime/parallel.h"

#include <algorithm>
#include <atomic>

namespace clvr {

std::vector<glm::vec4> sobelGradientVolume(const Volume& v)
{
    const glm::ivec3 n = v.dims;
    std::vector<glm::vec4> out(v.voxelCount());
    const double w[3] = {0.25, 0.5, 0.25};  // smoothing (1, 2, 1) / 4 across the derivative axis
    std::atomic<int> nextSlice{0};
    auto worker = [&] {
        for (int k; (k = nextSlice.fetch_add(1)) < n.z;) {
            for (int j = 0; j < n.y; ++j) {
                for (int i = 0; i < n.x; ++i) {
                    const glm::ivec3 p(i, j, k);
                    glm::dvec3 g(0.0);
                    for (int a = 0; a < 3; ++a) {
                        const int b = (a + 1) % 3, c = (a + 2) % 3;
                        // Neighbours along a, clamped: their index distance is 2 inside, 1 at a face.
                        glm::ivec3 lo = p, hi = p;
                        lo[a] = std::max(p[a] - 1, 0);
                        hi[a] = std::min(p[a] + 1, n[a] - 1);
                        double sum = 0.0;
                        for (int db = -1; db <= 1; ++db) {
                            for (int dc = -1; dc <= 1; ++dc) {
                                glm::ivec3 qlo = lo, qhi = hi;
                                qlo[b] = qhi[b] = std::clamp(p[b] + db, 0, n[b] - 1);
                                qlo[c] = qhi[c] = std::clamp(p[c] + dc, 0, n[c] - 1);
                                sum += w[db + 1] * w[dc + 1] *
                                       (static_cast<double>(v.at(qhi.x, qhi.y, qhi.z)) - v.at(qlo.x, qlo.y, qlo.z));
                            }
                        }
                        g[a] = sum / ((hi[a] - lo[a]) * v.spacing[a]);
                    }
                    out[(static_cast<std::size_t>(k) * n.y + j) * n.x + i] = glm::vec4(glm::vec3(g), v.at(i, j, k));
                }
            }
        }
    };
    runOnThreads(2, n.z, worker);
    return out;
}

}  // namespace clvr
