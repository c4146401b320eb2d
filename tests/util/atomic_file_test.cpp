#include "drt/util/atomic_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "temp_folder.h"

namespace drt {
namespace {

namespace fs = std::filesystem;

class AtomicFileTest : public test::TempFolderTest {
  protected:
    std::size_t entries() const {
        return static_cast<std::size_t>(
            std::distance(fs::directory_iterator(dir_), fs::directory_iterator()));
    }
    static std::string read(const fs::path& p) {
        std::ifstream in(p, std::ios::binary);
        return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    }
};

TEST_F(AtomicFileTest, ReplacesTheFileAndLeavesNoTemporary) {
    replace_file(dir_ / "a.txt", std::string_view("first"));
    replace_file(dir_ / "a.txt", std::string_view("second"));
    EXPECT_EQ(read(dir_ / "a.txt"), "second");
    EXPECT_EQ(entries(), 1u);
}

TEST_F(AtomicFileTest, FailureNamesThePathAndLeavesNothing) {
    try {
        replace_file(dir_ / "missing" / "a.txt", std::string_view("x"));
        FAIL();
    } catch (const FileWriteError& e) {
        EXPECT_EQ(std::string(e.what()), (dir_ / "missing" / "a.txt").string() +
                                             ": cannot create file: No such file or directory");
    }
    // A folder in the way: the temporary is written, the rename fails, the temporary goes.
    fs::create_directories(dir_ / "b.txt" / "inside");
    EXPECT_THROW(replace_file(dir_ / "b.txt", std::string_view("x")), FileWriteError);
    EXPECT_EQ(entries(), 1u);
}

TEST_F(AtomicFileTest, CheckReplaceableRefusesFoldersAndMissingFoldersAndLeavesNothing) {
    EXPECT_NO_THROW(check_replaceable(dir_ / "new.json"));
    EXPECT_EQ(entries(), 0u);
    try {
        check_replaceable(dir_);
        FAIL();
    } catch (const FileWriteError& e) {
        EXPECT_EQ(std::string(e.what()), dir_.string() + ": cannot write file: Is a directory");
    }
    EXPECT_THROW(check_replaceable(dir_ / "no" / "s.json"), FileWriteError);
}

}  // namespace
}  // namespace drt
