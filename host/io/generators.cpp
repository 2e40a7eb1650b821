// host/io/generators.cpp — procedural regular volumes on [-1,1]^3 (see generators.h for the definitions).
#include "host/io/generators.h"

#include "host/model/mesh.h"

#include "host/runtime/errors.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace clvr {

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Blob {
    glm::dvec3 center;
    double sigma;      // standard deviation, world units
    double amplitude;  // value at the center, before the other blobs' tails are added
};

// Fixed so that renders and tests are reproducible; asymmetric so that axis swaps show. The blobs are far
// apart for their widths: at one center the others add at most 0.019, so the peaks read 1.00, 0.76, 0.52
// and 0.27, and the clamp to 1 touches only a tiny neighbourhood of the first center (sum up to 1.00006).
constexpr std::array<Blob, 4> kBlobs{{
    {{-0.35, -0.25, -0.2}, 0.30, 1.00},
    {{0.40, 0.15, 0.25}, 0.22, 0.75},
    {{-0.05, 0.50, -0.45}, 0.18, 0.50},
    {{0.15, -0.45, 0.50}, 0.12, 0.25},
}};

}  // namespace

double marschnerLobb(const glm::dvec3& p)
{
    constexpr double fM = 6.0;     // f_M: frequency of the radial ripples
    constexpr double alpha = 0.25;
    const double r = std::sqrt(p.x * p.x + p.y * p.y);
    const double rhoR = std::cos(2.0 * kPi * fM * std::cos(kPi * r / 2.0));
    return (1.0 - std::sin(kPi * p.z / 2.0) + alpha * (1.0 + rhoR)) / (2.0 * (1.0 + alpha));
}

double sphereField(const glm::dvec3& p)
{
    return std::clamp(1.0 - glm::length(p), 0.0, 1.0);
}

double blobsField(const glm::dvec3& p)
{
    double sum = 0.0;
    for (const Blob& b : kBlobs) {
        const glm::dvec3 d = p - b.center;
        sum += b.amplitude * std::exp(-glm::dot(d, d) / (2.0 * b.sigma * b.sigma));
    }
    return std::min(sum, 1.0);
}

double kernelField(const glm::dvec3& p)
{
    const glm::dvec3 d = p - glm::dvec3(-0.5, -0.5, -0.5);
    return 0.1 + 0.9 * std::exp(-glm::dot(d, d) / (2.0 * 0.3 * 0.3));
}

TetMesh automatonMesh(int cells, int grid)
{
    if (grid < 1 || grid > 1024)
        throw InputError("mesh generator automaton: grid must be in [1, 1024], got " + std::to_string(grid));
    const std::uint64_t lattice = static_cast<std::uint64_t>(grid) * grid * grid;
    if (cells < 1 || static_cast<std::uint64_t>(cells) > lattice)
        throw InputError("mesh generator automaton: cells must be in [1, grid^3 = " + std::to_string(lattice) +
                         "], got " + std::to_string(cells));
    // The living cells: the first `cells` of a Fisher-Yates shuffle of the lattice (splitmix64, fixed
    // seed), run sparsely: only the entries a swap moved are stored, so memory follows `cells`, not the
    // lattice (a 1024^3 lattice would otherwise take 4 GiB for 8,000 cells).
    std::unordered_map<std::uint64_t, std::uint32_t> moved;
    const auto at = [&moved](std::uint64_t i) {
        const auto it = moved.find(i);
        return it == moved.end() ? static_cast<std::uint32_t>(i) : it->second;
    };
    std::uint64_t state = 0x5eed5eed5eedULL;
    const auto next = [&state] {
        std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
        return z ^ (z >> 31);
    };
    std::vector<std::uint32_t> order(static_cast<std::size_t>(cells));
    for (std::uint64_t i = 0; i < static_cast<std::uint64_t>(cells); ++i) {
        const std::uint64_t j = i + next() % (lattice - i);
        const std::uint32_t vi = at(i), vj = at(j);
        order[i] = vj;
        moved[j] = vi;  // position i is never read again
    }
    std::sort(order.begin(), order.end());

    TetMesh mesh;
    mesh.source = "generator automaton (" + std::to_string(cells) + " cells of " + std::to_string(grid) + "^3)";
    const double h = 2.0 / grid;
    // The cube's 6 faces as corner indices (bit 0: +x, bit 1: +y, bit 2: +z), each split along one diagonal.
    static const int kFaces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (int n = 0; n < cells; ++n) {
        const std::uint32_t c = order[static_cast<std::size_t>(n)];
        const glm::dvec3 lo(-1.0 + h * (c % grid), -1.0 + h * ((c / grid) % grid), -1.0 + h * (c / grid / grid));
        const auto base = static_cast<std::uint32_t>(mesh.points.size());
        for (int k = 0; k < 8; ++k) {
            mesh.points.push_back(lo + h * glm::dvec3(k & 1, (k >> 1) & 1, (k >> 2) & 1));
            mesh.scalars.push_back(0.0);
        }
        mesh.points.push_back(lo + 0.5 * h);
        mesh.scalars.push_back(1.0);
        for (const auto& f : kFaces) {
            mesh.tets.push_back(glm::uvec4(base + 8, base + f[0], base + f[1], base + f[2]));
            mesh.tets.push_back(glm::uvec4(base + 8, base + f[0], base + f[2], base + f[3]));
        }
    }
    mesh.tetsRead = mesh.tets.size();
    return mesh;
}

double atmosphereField(const glm::dvec3& p)
{
    // p in [-1,1]^3 read as normalized spherical coordinates (u, v, w) = (p + 1) / 2 (the
    // spherical technique's grid axes, host/render/grid/spherical.h): phi = 2 pi u, theta = pi v.
    const double phi = kPi * (p.x + 1.0), theta = 0.5 * kPi * (p.y + 1.0), w = 0.5 * (p.z + 1.0);
    const double layer = std::exp(-std::pow((w - 0.55) / 0.22, 2.0));
    const double bands = 0.5 + 0.5 * std::cos(6.0 * theta + 1.2 * std::sin(theta) * std::cos(3.0 * phi));
    return std::clamp(layer * bands, 0.0, 1.0);
}

Volume generateVolume(const std::string& name, glm::ivec3 dims)
{
    double (*field)(const glm::dvec3&) = nullptr;
    if (name == "marschner-lobb")
        field = marschnerLobb;
    else if (name == "sphere")
        field = sphereField;
    else if (name == "blobs")
        field = blobsField;
    else if (name == "atmosphere")
        field = atmosphereField;
    else
        throw InputError("generator \"" + name + "\": unknown (marschner-lobb, sphere, blobs and atmosphere exist)");

    const std::string source = "generator " + name;
    std::uint64_t count = 1;
    for (int a = 0; a < 3; ++a) {
        if (dims[a] < 2)
            throw InputError(source + ": dims[" + std::to_string(a) + "] is " + std::to_string(dims[a]) +
                             ", must be at least 2");
        count *= static_cast<std::uint64_t>(dims[a]);  // each factor < 2^31: no overflow in 3 factors
    }
    if (count > (std::uint64_t(1) << 34))
        throw InputError(source + ": " + std::to_string(dims.x) + "x" + std::to_string(dims.y) + "x" +
                         std::to_string(dims.z) + " is too large (more than 2^34 grid points)");
    checkHostMemoryForVoxels(source, count);

    Volume v;
    v.dims = dims;
    v.spacing = 2.0 / glm::dvec3(dims - 1);
    v.origin = glm::dvec3(-1.0);
    v.source = source;
    v.values.resize(static_cast<std::size_t>(count));
    std::size_t n = 0;
    for (int k = 0; k < dims.z; ++k)
        for (int j = 0; j < dims.y; ++j)
            for (int i = 0; i < dims.x; ++i) {
                // Computed from the index, not by accumulating spacing: the last point is exactly 1.
                const glm::dvec3 p = -1.0 + 2.0 * glm::dvec3(i, j, k) / glm::dvec3(dims - 1);
                v.values[n++] = static_cast<float>(field(p));
            }
    v.validate();
    return v;
}

}  // namespace clvr
