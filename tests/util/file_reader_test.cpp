#include "drt/util/file_reader.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "temp_folder.h"

namespace drt {
namespace {

namespace fs = std::filesystem;

class FileReaderTest : public test::TempFolderTest {
  protected:
    fs::path write(const std::string& name, const std::string& text) const {
        const fs::path p = dir_ / name;
        std::ofstream(p, std::ios::binary) << text;
        return p;
    }
};

// The problem a read of `path` fails with; fails the test when it succeeds.
template <class Read>
FileReadError failure(Read read) {
    try {
        read();
    } catch (const FileReadError& e) {
        return e;
    }
    ADD_FAILURE() << "read succeeded";
    return FileReadError(FileProblem::cannot_open, 0);
}

TEST_F(FileReaderTest, ReadsEveryByteUpToTheBoundAndRefusesOneMore) {
    const std::string text("a\0b\r\n\xff", 6);
    const fs::path p = write("f.bin", text);
    EXPECT_EQ(read_text_file(p, 6), text);
    const std::vector<unsigned char> bytes = read_binary_file(p, 6, FileKinds::regular_only);
    EXPECT_EQ(std::string(bytes.begin(), bytes.end()), text);
    const FileReadError e = failure([&] { read_text_file(p, 5); });
    EXPECT_EQ(e.problem(), FileProblem::too_large);
    EXPECT_EQ(e.reason(), "");
}

TEST_F(FileReaderTest, AFileLargerThanTheReadBufferComesBackWhole) {
    std::string text;
    for (int i = 0; i < 200000; ++i) text += static_cast<char>('a' + i % 26);
    const fs::path p = write("big.txt", text);
    EXPECT_EQ(read_text_file(p, text.size()), text);
    EXPECT_EQ(failure([&] { read_text_file(p, text.size() - 1); }).problem(),
              FileProblem::too_large);
}

TEST(FileReader, AnEndlessDeviceIsCutOffAtTheBound) {
    const FileReadError e = failure([] { read_text_file("/dev/zero", 100000); });
    EXPECT_EQ(e.problem(), FileProblem::too_large);
    EXPECT_TRUE(read_text_file("/dev/null", 10).empty());
}

TEST_F(FileReaderTest, AMissingFileCannotBeOpenedAndSaysWhy) {
    const FileReadError e = failure([&] { read_text_file(dir_ / "missing", 10); });
    EXPECT_EQ(e.problem(), FileProblem::cannot_open);
    EXPECT_EQ(e.reason(), "No such file or directory");
    EXPECT_STREQ(e.what(), "cannot open file: No such file or directory");
}

TEST_F(FileReaderTest, AFolderFailsWhenReadOrIsRefusedWhenOnlyRegularFilesAreWanted) {
    const FileReadError any = failure([&] { read_text_file(dir_, 10); });
    EXPECT_EQ(any.problem(), FileProblem::cannot_read);
    EXPECT_EQ(any.reason(), "Is a directory");
    EXPECT_EQ(failure([&] { read_binary_file(dir_, 10, FileKinds::regular_only); }).problem(),
              FileProblem::is_folder);
    EXPECT_EQ(
        failure([&] { read_binary_file("/dev/null", 10, FileKinds::regular_only); }).problem(),
        FileProblem::not_regular_file);
}

}  // namespace
}  // namespace drt
