// host/cluster/world.h — the MPI job clvr runs in (docs/cluster.md): rank, size, the node-local rank
// that picks a rank's OpenCL device, and agreement on failure, so that a rank that fails (a missing file
// on one node, a bad scene, a device error, out of memory) makes every rank stop with the same one-line
// error and exit status instead of leaving the others waiting in a collective. Built with CLVR_MPI only.
#pragma once

#include <exception>
#include <functional>
#include <string>
#include <vector>

namespace clvr::cluster {

// True when this process was started by an MPI launcher (mpirun/mpiexec of Open MPI, Slurm's srun with
// PMI or PMIx): then `clvr render` renders as one rank of a job. A plain `clvr render` never starts MPI.
bool launchedByMpi();

// MPI_Init_thread (funneled) on construction, MPI_Finalize on destruction. One per process.
class World {
public:
    World(int* argc, char*** argv);
    ~World();
    World(const World&) = delete;
    World& operator=(const World&) = delete;

    int rank() const { return rank_; }
    int size() const { return size_; }
    // This rank's index among the ranks on its node (MPI_COMM_TYPE_SHARED), and how many share the node.
    int nodeRank() const { return nodeRank_; }
    int nodeSize() const { return nodeSize_; }

    // Runs `step` on every rank, then agrees: when it threw on any rank, every rank throws the error of the
    // lowest failing rank (same kind, same message, "rank R: " in front when R is not 0), so every rank
    // leaves with the same message and exit status. A collective: every rank must call it.
    void agree(const std::function<void()>& step);

    // MPI_Barrier.
    void barrier() const;
    // Gathers one double per rank on rank 0 (others get an empty vector).
    std::vector<double> gather(double value) const;
    // Every rank's value, in rank order, on every rank.
    std::vector<double> allGather(double value) const;
    // Gathers every rank's floats on rank 0, in rank order (others get an empty vector).
    std::vector<float> gather(const std::vector<float>& mine) const;
    // The largest value over all ranks, on every rank.
    double maxOver(double value) const;

private:
    int rank_ = 0, size_ = 1, nodeRank_ = 0, nodeSize_ = 1;
    bool agreedFailure_ = false;  // agree() threw the job's common error: finalize normally
};

}  // namespace clvr::cluster
