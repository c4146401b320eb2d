// Signals are process-wide, so each test runs its scenario in a forked child and reads the
// verdict from the child's exit status and the files it leaves.
#include "drt/util/interrupt.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "temp_folder.h"

namespace drt {
namespace {

namespace fs = std::filesystem;

class InterruptTest : public test::TempFolderTest {
  protected:
    // The child's wait status after running `body` (exit 0 when body returns).
    static int in_child(const std::function<void()>& body) {
        const pid_t pid = fork();
        if (pid == 0) {
            body();
            _exit(0);
        }
        int status = 0;
        waitpid(pid, &status, 0);
        return status;
    }
};

TEST_F(InterruptTest, SignalRemovesRegisteredTemporariesAndEndsTheProcessAsTheSignalWould) {
    for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
        const fs::path tmp = dir_ / ".out.png.tmp-1-2", kept = dir_ / "unregistered";
        std::ofstream(kept) << "x";
        const int status = in_child([&] {
            install_interrupt_handlers();
            const TemporaryFileGuard guard(tmp);
            std::ofstream(tmp) << "partial";
            raise(sig);
            _exit(3);  // not reached: the signal ends the process
        });
        ASSERT_TRUE(WIFSIGNALED(status)) << sig;
        EXPECT_EQ(WTERMSIG(status), sig);
        EXPECT_FALSE(fs::exists(tmp)) << sig;
        EXPECT_TRUE(fs::exists(kept));
    }
}

TEST_F(InterruptTest, ReleasedGuardNoLongerRemovesItsFile) {
    const fs::path renamed = dir_ / "out.png";
    const int status = in_child([&] {
        install_interrupt_handlers();
        { const TemporaryFileGuard guard(renamed); }
        std::ofstream(renamed) << "done";
        raise(SIGTERM);
    });
    EXPECT_TRUE(WIFSIGNALED(status));
    EXPECT_TRUE(fs::exists(renamed));
}

TEST_F(InterruptTest, UnderACooperativeStopASignalOnlyRaisesTheFlag) {
    const fs::path tmp = dir_ / ".tmp";
    const int status = in_child([&] {
        install_interrupt_handlers();
        const CooperativeStop stop;
        const TemporaryFileGuard guard(tmp);
        std::ofstream(tmp) << "partial";
        if (stop_signal().load() != 0) _exit(4);
        raise(SIGINT);
        _exit(stop_signal().load() == SIGINT ? 0 : 5);
    });
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0);
    EXPECT_FALSE(fs::exists(tmp));  // temporaries go at the first signal all the same
}

TEST_F(InterruptTest, SecondSignalEndsTheProcessEvenUnderACooperativeStop) {
    const int status = in_child([&] {
        install_interrupt_handlers();
        const CooperativeStop stop;
        raise(SIGTERM);
        raise(SIGTERM);
        _exit(6);
    });
    ASSERT_TRUE(WIFSIGNALED(status));
    EXPECT_EQ(WTERMSIG(status), SIGTERM);
}

}  // namespace
}  // namespace drt
