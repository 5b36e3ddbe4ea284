// Operator key files (msgs/auth/operator_key.hpp): made fresh and private, and refused with the
// file's name and the reason when anyone else could read or change them.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "msgs/auth/operator_key.hpp"

namespace hsa::msgs {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class OperatorKeyFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/hsa-keys-XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;  // mode 0700
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text, mode_t mode = 0600) {
    const std::string path = dir_ + "/" + name;
    std::ofstream(path) << text;
    chmod(path.c_str(), mode);
    return path;
  }

  // The message of the KeyFileError that `f` throws, or "" when it throws none.
  template <typename F>
  static std::string refusal(F f) {
    try {
      f();
    } catch (const KeyFileError& e) {
      return e.what();
    }
    return "";
  }

  std::string dir_;
  const std::string hex_ = "0123456789abcdeffedcba98765432100123456789abcdeffedcba9876543210";
};

TEST_F(OperatorKeyFiles, KeygenWritesAPrivateRandomKeyThatReadsBack) {
  const std::string a = write_new_key(dir_, "alice");
  const std::string b = write_new_key(dir_, "bob");
  EXPECT_EQ(a, dir_ + "/alice.key");
  struct stat st {};
  ASSERT_EQ(stat(a.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0600u);
  EXPECT_EQ(fs::file_size(a), 65u);  // 64 hex digits and a newline
  const OperatorKey ka = read_key_file(a);
  const OperatorKey kb = read_key_file(b);
  EXPECT_EQ(ka.operator_id, "alice");
  EXPECT_EQ(kb.operator_id, "bob");
  EXPECT_NE(ka.key, kb.key);
  EXPECT_NE(ka.key, Key{});
}

TEST_F(OperatorKeyFiles, KeygenNeverOverwritesAndChecksTheName) {
  const std::string a = write_new_key(dir_, "alice");
  const Key before = read_key_file(a).key;
  EXPECT_THAT(refusal([&] { write_new_key(dir_, "alice"); }), HasSubstr("exists already"));
  EXPECT_EQ(read_key_file(a).key, before);
  for (const char* bad : {"", ".hidden", "a/b", "x y", "0123456789012345678901234567890123"}) {
    EXPECT_THAT(refusal([&] { write_new_key(dir_, bad); }), HasSubstr("operator id")) << bad;
  }
}

TEST_F(OperatorKeyFiles, AKeyOthersCanReadIsRefusedWithItsMode) {
  const std::string path = write("alice.key", hex_ + "\n", 0640);
  const std::string why = refusal([&] { (void)read_key_file(path); });
  EXPECT_THAT(why, HasSubstr(path));
  EXPECT_THAT(why, HasSubstr("mode 0640"));
  EXPECT_THAT(why, HasSubstr("chmod 600"));
  chmod(path.c_str(), 0604);
  EXPECT_THAT(refusal([&] { (void)read_key_file(path); }), HasSubstr("mode 0604"));
  chmod(path.c_str(), 0400);
  EXPECT_EQ(refusal([&] { (void)read_key_file(path); }), "");
}

TEST_F(OperatorKeyFiles, AKeyOfAnotherUserIsRefused) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to give a file to another user";
  const std::string path = write("alice.key", hex_ + "\n");
  ASSERT_EQ(chown(path.c_str(), 12345, static_cast<gid_t>(-1)), 0);
  EXPECT_THAT(refusal([&] { (void)read_key_file(path); }), HasSubstr("owned by uid 12345"));
}

TEST_F(OperatorKeyFiles, ALinkOrAMalformedKeyIsRefused) {
  const std::string target = write("real.key", hex_ + "\n");
  fs::create_symlink(target, dir_ + "/link.key");
  EXPECT_THAT(refusal([&] { (void)read_key_file(dir_ + "/link.key"); }), HasSubstr("symbolic link"));
  for (const std::string& text : {std::string(63, 'a'), std::string(65, 'a'), std::string(63, 'a') + "g",
                                  hex_ + "\n\n", std::string()}) {
    const std::string path = write("bad.key", text);
    EXPECT_THAT(refusal([&] { (void)read_key_file(path); }), HasSubstr("64 hexadecimal digits")) << text;
    fs::remove(path);
  }
  EXPECT_THAT(refusal([&] { (void)read_key_file(write("alice.txt", hex_)); }), HasSubstr("<operator>.key"));
  EXPECT_THAT(refusal([&] { (void)read_key_file(dir_ + "/none.key"); }), HasSubstr("cannot open"));
}

TEST_F(OperatorKeyFiles, AWeakKeyIsRefusedWithTheReason) {
  const std::string zero = write("zero.key", std::string(64, '0') + "\n");
  std::string why = refusal([&] { (void)read_key_file(zero); });
  EXPECT_THAT(why, HasSubstr(zero));
  EXPECT_THAT(why, HasSubstr("weak key (all zero)"));
  std::string repeated;
  for (int i = 0; i < 32; ++i) repeated += "a5";
  const std::string same = write("same.key", repeated + "\n");
  why = refusal([&] { (void)read_key_file(same); });
  EXPECT_THAT(why, HasSubstr(same));
  EXPECT_THAT(why, HasSubstr("one byte repeated 32 times"));
  // One byte different is no longer "repeated": the check is exactly what it says.
  repeated[63] = '4';
  EXPECT_EQ(refusal([&] { (void)read_key_file(write("almost.key", repeated + "\n")); }), "");
}

TEST_F(OperatorKeyFiles, AShortKeyIsRefusedWithItsLength) {
  const std::string path = write("short.key", hex_.substr(0, 40) + "\n");
  const std::string why = refusal([&] { (void)read_key_file(path); });
  EXPECT_THAT(why, HasSubstr(path));
  EXPECT_THAT(why, HasSubstr("is too short: 41 characters, fewer than a 32-byte key's"));
  EXPECT_THAT(why, HasSubstr("64 hexadecimal digits"));
}

TEST(KeyWeakness, NamesAllZeroAndRepeatedBytesOnly) {
  Key key{};
  EXPECT_EQ(key_weakness(key), "all zero");
  key.fill(0xff);
  EXPECT_EQ(key_weakness(key), "one byte repeated 32 times");
  key[31] = 0xfe;
  EXPECT_EQ(key_weakness(key), "");
}

TEST_F(OperatorKeyFiles, KeygenMakesNoWeakKey) {
  for (int i = 0; i < 20; ++i) {
    const OperatorKey k = read_key_file(write_new_key(dir_, "op" + std::to_string(i)));
    EXPECT_EQ(key_weakness(k.key), "");
  }
}

TEST_F(OperatorKeyFiles, AKeyFolderHoldsOnlyItsOwnersKeys) {
  write_new_key(dir_, "bob");
  write_new_key(dir_, "alice");
  write("README", "not a key");
  const auto keys = read_key_dir(dir_);
  ASSERT_EQ(keys.size(), 2u);
  EXPECT_EQ(keys[0].operator_id, "alice");
  EXPECT_EQ(keys[1].operator_id, "bob");

  chmod(dir_.c_str(), 0770);
  EXPECT_THAT(refusal([&] { (void)read_key_dir(dir_); }), HasSubstr("lets others add keys"));
  chmod(dir_.c_str(), 0755);  // readable by others is fine: the keys themselves are 0600
  EXPECT_EQ(refusal([&] { (void)read_key_dir(dir_); }), "");
  // One bad key spoils the folder: hsad does not start with a key it would have to skip.
  chmod((dir_ + "/bob.key").c_str(), 0644);
  EXPECT_THAT(refusal([&] { (void)read_key_dir(dir_); }), HasSubstr("bob.key"));
}

TEST_F(OperatorKeyFiles, AnEmptyOrMissingFolderIsRefused) {
  EXPECT_THAT(refusal([&] { (void)read_key_dir(dir_); }), HasSubstr("hsactl keygen"));
  EXPECT_THAT(refusal([&] { (void)read_key_dir(dir_ + "/none"); }), HasSubstr("cannot open the key folder"));
}

}  // namespace
}  // namespace hsa::msgs
