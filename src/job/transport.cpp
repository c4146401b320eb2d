#include "drt/job/transport.h"

#include <dlfcn.h>

#include <stdexcept>
#include <string>

namespace drt {

SharedModule::SharedModule(const std::filesystem::path& file)
    // RTLD_GLOBAL: Open MPI's own plugins, which it loads in turn, look for libmpi's symbols
    // there. RTLD_NODELETE: an MPI library is not made to be unloaded after MPI_Finalize (its
    // exit handlers would point nowhere), so closing only drops the reference.
    : handle_(dlopen(file.c_str(), RTLD_NOW | RTLD_GLOBAL | RTLD_NODELETE)), file_(file) {
    if (handle_ == nullptr) {
        const char* why = dlerror();
        // dlerror's message names the file.
        throw std::runtime_error(why != nullptr ? why : "cannot load " + file.string());
    }
}

SharedModule::~SharedModule() {
    dlclose(handle_);
}

void* SharedModule::symbol(const char* name) const {
    void* found = dlsym(handle_, name);
    if (found == nullptr) {
        throw std::runtime_error(file_.string() + " has no " + name + ": not a drt MPI module");
    }
    return found;
}

std::filesystem::path mpi_module_path() {
    std::error_code error;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
    return (error ? std::filesystem::path() : self.parent_path()) / "drt_mpi.so";
}

std::unique_ptr<Transport> start_mpi(const SharedModule& module) {
    // The one way from a data pointer that dlsym returns to the function it names.
    const auto start = reinterpret_cast<StartMpi>(module.symbol(kStartMpiSymbol));
    std::unique_ptr<Transport> out;
    start(&out);
    if (!out) throw std::runtime_error("MPI did not start");
    return out;
}

}  // namespace drt
