// host/cluster/world.cpp — MPI start-up, node-local ranks and failure agreement (host/cluster/world.h).
#include "host/cluster/world.h"

#include "host/runtime/errors.h"

#include <CL/opencl.hpp>
#include <mpi.h>

#include <cstdlib>
#include <new>

namespace clvr::cluster {
namespace {

// The kinds of failure tools/clvr.cpp tells apart (each has its exit status), as sent between ranks.
enum class Kind : int { None = 0, Input, Device, Internal };

struct Failure {
    Kind kind = Kind::None;
    std::string message;
};

Failure classify(const std::exception_ptr& error)
{
    try {
        std::rethrow_exception(error);
    } catch (const InputError& e) {
        return {Kind::Input, e.what()};
    } catch (const DeviceError& e) {  // BuildError too: its log stays with the rank that built
        return {Kind::Device, e.what()};
    } catch (const cl::Error& e) {
        return {Kind::Device, std::string(e.what()) + " failed: " + clErrorName(e.err())};
    } catch (const std::bad_alloc&) {
        return {Kind::Device, "out of host memory"};
    } catch (const std::exception& e) {
        return {Kind::Internal, e.what()};
    }
}

[[noreturn]] void raise(const Failure& f)
{
    switch (f.kind) {
    case Kind::Input:
        throw InputError(f.message);
    case Kind::Device:
        throw DeviceError(f.message);
    default:
        throw InternalError(f.message);
    }
}

}  // namespace

bool launchedByMpi()
{
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "MPI_LOCALNRANKS"})
        if (std::getenv(name))
            return true;
    return false;
}

World::World(int* argc, char*** argv)
{
    int provided = 0;
    MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    MPI_Comm node;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &node);
    MPI_Comm_rank(node, &nodeRank_);
    MPI_Comm_size(node, &nodeSize_);
    MPI_Comm_free(&node);
}

World::~World()
{
    // An error that did not go through agree() leaves the other ranks in a collective: end the job.
    if (std::uncaught_exceptions() > 0 && !agreedFailure_)
        MPI_Abort(MPI_COMM_WORLD, 4);
    MPI_Finalize();
}

void World::agree(const std::function<void()>& step)
{
    Failure mine;
    try {
        step();
    } catch (...) {
        mine = classify(std::current_exception());
    }
    // The lowest failing rank speaks for all: its kind and message, broadcast.
    const int candidate = mine.kind == Kind::None ? size_ : rank_;
    int speaker = size_;
    MPI_Allreduce(&candidate, &speaker, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (speaker == size_)
        return;
    int header[2] = {static_cast<int>(mine.kind), static_cast<int>(mine.message.size())};
    MPI_Bcast(header, 2, MPI_INT, speaker, MPI_COMM_WORLD);
    Failure agreed{static_cast<Kind>(header[0]), std::string(static_cast<std::size_t>(header[1]), '\0')};
    if (rank_ == speaker)
        agreed.message = mine.message;
    MPI_Bcast(agreed.message.data(), header[1], MPI_CHAR, speaker, MPI_COMM_WORLD);
    if (speaker != 0)
        agreed.message = "rank " + std::to_string(speaker) + ": " + agreed.message;
    agreedFailure_ = true;
    raise(agreed);
}

void World::barrier() const
{
    MPI_Barrier(MPI_COMM_WORLD);
}

std::vector<double> World::gather(double value) const
{
    std::vector<double> all(rank_ == 0 ? static_cast<std::size_t>(size_) : 0);
    MPI_Gather(&value, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    return all;
}

std::vector<double> World::allGather(double value) const
{
    std::vector<double> all(static_cast<std::size_t>(size_));
    MPI_Allgather(&value, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, MPI_COMM_WORLD);
    return all;
}

std::vector<float> World::gather(const std::vector<float>& mine) const
{
    const int count = static_cast<int>(mine.size());
    std::vector<int> counts(static_cast<std::size_t>(size_)), displacements(static_cast<std::size_t>(size_));
    MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::size_t total = 0;
    for (int r = 0; r < size_ && rank_ == 0; ++r) {
        displacements[static_cast<std::size_t>(r)] = static_cast<int>(total);
        total += static_cast<std::size_t>(counts[static_cast<std::size_t>(r)]);
    }
    std::vector<float> all(total);
    MPI_Gatherv(mine.data(), count, MPI_FLOAT, all.data(), counts.data(), displacements.data(), MPI_FLOAT, 0,
                MPI_COMM_WORLD);
    return all;
}

double World::maxOver(double value) const
{
    double out = value;
    MPI_Allreduce(&value, &out, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    return out;
}

}  // namespace clvr::cluster
