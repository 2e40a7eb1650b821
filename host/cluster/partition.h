// host/cluster/partition.h — sort-last data distribution (docs/cluster.md): the data set cut into one
// part per rank by a k-d tree, each part rendered on its own into premultiplied RGBA, and the parts'
// images composited "over" in the view's visibility order of the parts, which the tree gives exactly
// for any eye (a ray crosses each splitting plane at most once). No MPI here: the cluster layer
// (host/cluster/world.h, compositor.h) moves the images, the tests composite on one process.
//
// Regular grids: the grid's cells are split, every part keeps its cells' grid points, so two parts share
// one layer of points and trilinear sampling is seamless; each sample belongs to exactly one part
// (host/model/volume.h's GridPart). Tetrahedral meshes: the bounding box is split at tetrahedron-centroid
// medians, every part keeps the tetrahedra whose bounding boxes meet its box, and integrates each ray
// only inside its box (host/model/mesh.h's MeshPart).
#pragma once

#include "host/model/camera.h"
#include "host/model/image.h"
#include "host/model/mesh.h"
#include "host/model/volume.h"

#include <glm/glm.hpp>

#include <functional>
#include <vector>

namespace clvr {

// A k-d tree over parts 0..n-1. Node 0 is the root; a leaf names its part.
struct KdTree {
    struct Node {
        int axis = -1;        // -1: a leaf
        double split = 0.0;   // world coordinate of the splitting plane on `axis`
        int below = -1;       // child on the side with coordinates < split
        int above = -1;       // child on the side >= split
        int part = -1;        // leaves only
    };
    std::vector<Node> nodes;

    // The parts in visibility order for `camera`, front (nearest the eye) first: at each plane the side
    // holding the eye (perspective) or the side the view direction comes from (parallel) goes first.
    // Exact for every eye position, inside the data's bounds too.
    std::vector<int> frontToBack(const Camera& camera) const;

    // The part whose box holds p (a point on a splitting plane belongs to the side above it).
    int partAt(const glm::dvec3& p) const;
};

// What rendering the data near a world point costs, per unit volume (host/cluster/balance.h): where a
// partition cuts when it balances cost rather than data.
using CostDensity = std::function<double(const glm::dvec3&)>;

// A regular grid cut into n parts: part p holds the grid points [lo[p], hi[p]] (inclusive) per axis.
struct GridPartition {
    KdTree tree;
    std::vector<glm::ivec3> lo, hi;
};

// Splits the cells of a grid with `dims` points and `spacing` into n parts, halving the rank count at each
// level and cutting the longest axis (in world units) in proportion, so parts differ by at most one cell
// layer per cut. With `cost`, each cut is on the same axis at the cell layer that gives the two sides
// cost in proportion to their rank counts instead (a layer's cost: the mean of `cost` over up to 16x16
// of its cells' centers, times its volume). InputError when the grid has too few cells for n parts
// (each needs at least one cell per axis).
GridPartition partitionGrid(const glm::ivec3& dims, const glm::dvec3& origin, const glm::dvec3& spacing, int n,
                            const CostDensity& cost = {});

// The cost of each part of `partition`: the mean of `cost` over up to 16^3 of its cells' centers, times
// its volume (the same measure partitionGrid balances).
std::vector<double> gridPartCosts(const GridPartition& partition, const glm::dvec3& origin, const glm::dvec3& spacing,
                                  const CostDensity& cost);

// Part p of `volume` as its own Volume: the grid points [lo[p], hi[p]] plus `ghost` (0 or 1) more layers
// on each side where the grid goes on (GridPart set, ghostLo/ghostHi saying how many it holds). The part
// owns the samples of [lo[p], hi[p]] either way; the ghost layer gives planes' and blend's Sobel
// gradients their neighbours (TechniqueInfo::sortLastGhost).
Volume cutGridPart(const Volume& volume, const GridPartition& partition, int p, int ghost = 0);

// The grid points cutGridPart keeps of a grid with `dims` for part p (its own points and the ghost
// layers), and the GridPart that places a volume holding exactly those points in the whole grid (whose
// first point is at `origin`). A rank that reads only its part (loadVolumeRegion) reads this region and
// sets this placement: the same Volume cutGridPart would cut from the whole.
GridRegion gridPartRegion(const GridPartition& partition, const glm::ivec3& dims, int p, int ghost = 0);
GridPart gridPartPlacement(const GridPartition& partition, const glm::ivec3& dims, const glm::dvec3& origin, int p,
                           int ghost = 0);

// A tetrahedral mesh cut into n k-d boxes (part p: [lo[p], hi[p]]) of its bounding box.
struct MeshPartition {
    KdTree tree;
    std::vector<glm::dvec3> lo, hi;
};

// Splits the mesh's bounding box into n boxes, each cut on the longest axis at the centroid quantile
// that gives the two sides tetrahedra in proportion to their rank counts — or, with `tetCost` (one
// non-negative cost per tetrahedron), cost in proportion. InputError for n < 1 or an empty mesh.
MeshPartition partitionMesh(const TetMesh& mesh, int n, const std::vector<double>& tetCost = {});

// The centroid of each tetrahedron of `mesh`: what partitionMesh splits and what decides a tetrahedron's
// part when costs are summed per part.
std::vector<glm::dvec3> tetCentroids(const TetMesh& mesh);

// Part p of `mesh`: the tetrahedra whose bounding boxes meet part p's box (points renumbered, MeshPart
// set with the box and the full mesh's box). The mesh must have passed checkMesh.
TetMesh cutMeshPart(const TetMesh& mesh, const MeshPartition& partition, int p);

// premultiplied "over", front first: out = sum of images[k] * prod_{j<k} (1 - A_j). Every image the same
// size; each pixel (C, A) with C premultiplied. The one-process reference for IceT's ordered blend.
Image4f compositeOver(const std::vector<const Image4f*>& frontToBack);

// I + (1 - A) * background, alpha kept: what every renderer does last, for a composited image.
void addBackground(Image4f& image, const glm::dvec3& background);

// Sort-first (docs/cluster.md): image rows per rank for the next frame, top band first. `rows` and `ms`
// are the previous frame's rows and render times per rank; no time yet (all 0): equal shares, the first
// ranks one row more. Else each row costs its rank's time over its rows (seeds/001 §6's reference
// balances tiles by the previous frame's cost the same way) and the new bands cut the cumulative cost
// into equal parts; every rank keeps at least one row. The counts add up to `height`.
std::vector<int> balanceRows(int height, const std::vector<int>& rows, const std::vector<double>& ms);

}  // namespace clvr
