// Plugin loading: what is found where, and every way a plugin can be refused.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include <dyad/catalog.hpp>

namespace fs = std::filesystem;

namespace dyad {
namespace {

const std::string kExamples = std::string(DYAD_TEST_PLUGIN_DIR) + "/dyad_examples.so";

fs::path TempDir(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("dyad_catalog_" + std::to_string(getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(Catalog, LoadsAPluginFileAndDescribesItsTypes) {
  Catalog c;
  ASSERT_TRUE(c.Load(kExamples).ok());
  const CatalogEntry* src = c.Find("counter_source");
  ASSERT_NE(src, nullptr);
  EXPECT_EQ(src->type.plugin_path, fs::canonical(kExamples).string());
  ASSERT_EQ(src->spec.outputs().size(), 1u);
  EXPECT_EQ(src->spec.outputs()[0].type->name, "dyad::msg::Counter");
  EXPECT_NE(c.FindMessageType("Counter"), nullptr);
  EXPECT_NE(c.FindMessageType("dyad::msg::HumanInput"), nullptr);  // built-in IDL, no port needed
  EXPECT_EQ(c.FindMessageType("Nothing"), nullptr);
}

TEST(Catalog, LoadingTheSameFileTwiceIsHarmless) {
  Catalog c;
  ASSERT_TRUE(c.Load(kExamples).ok());
  EXPECT_TRUE(c.Load(kExamples).ok());
}

TEST(Catalog, MissingPathIsNotFoundNamingIt) {
  Catalog c;
  Status s = c.Load("/nonexistent/plugin.so");
  EXPECT_EQ(s.code(), Status::Code::kNotFound);
  EXPECT_NE(s.message().find("/nonexistent/plugin.so"), std::string::npos) << s.message();
}

TEST(Catalog, SharedLibraryWithoutEntryPointIsRefused) {
  Catalog c;
  Status s = c.Load(DYAD_TEST_NON_PLUGIN);
  EXPECT_EQ(s.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(s.message().find("not a dyad plugin"), std::string::npos) << s.message();
}

TEST(Catalog, OtherAbiVersionIsRefusedNamingBothVersions) {
  Catalog c;
  Status s = c.Load(DYAD_TEST_WRONG_ABI_PLUGIN);
  EXPECT_EQ(s.code(), Status::Code::kFailedPrecondition);
  EXPECT_NE(s.message().find("ABI 999"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("ABI " + std::to_string(kPluginAbiVersion)), std::string::npos) << s.message();
}

TEST(Catalog, FileThatIsNotALibraryIsRefused) {
  const fs::path dir = TempDir("garbage");
  const fs::path f = dir / "garbage.so";
  std::ofstream(f) << "not an ELF file";
  Catalog c;
  Status s = c.Load(f.string());
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find(f.string()), std::string::npos) << s.message();
  fs::remove_all(dir);
}

TEST(Catalog, DyadPluginPathComesBeforeBuiltinsAndConflictsAreReported) {
  const fs::path dir = TempDir("env");
  fs::copy_file(kExamples, dir / "copy.so");
  setenv("DYAD_PLUGIN_PATH", dir.c_str(), 1);
  Catalog c;
  Status s = c.LoadDefault({});
  unsetenv("DYAD_PLUGIN_PATH");
  ASSERT_NE(c.Find("counter_sink"), nullptr);
  EXPECT_EQ(c.Find("counter_sink")->type.plugin_path, fs::canonical(dir / "copy.so").string());
  // The built-in copy registers the same names: kept out, and said.
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("already registered by " + fs::canonical(dir / "copy.so").string()), std::string::npos)
      << s.message();
  fs::remove_all(dir);
}

// Path() only means something on strings: a plugin marking a number as a path is refused at
// load time, naming the plugin, the type and the param; its other types still register.
class NumberMarkedAsPath : public Component {
 public:
  static void Describe(ComponentSpec& spec) { spec.Param("gain", 0.5).Path(); }
  Status Configure(Context&) override { return Status::OK(); }
  Status Step(const StepInfo&) override { return Status::OK(); }
};
class FileParam : public Component {
 public:
  static void Describe(ComponentSpec& spec) { spec.Param("file", "").Path(); }
  Status Configure(Context&) override { return Status::OK(); }
  Status Step(const StepInfo&) override { return Status::OK(); }
};

TEST(Catalog, PathOnANonStringParamIsRefused) {
  Catalog catalog;
  const Status s = catalog.Register("test-plugin", [](PluginRegistry& r) {
    r.Add<NumberMarkedAsPath>("bad_path");
    r.Add<FileParam>("good_path");
  });
  EXPECT_EQ(s.code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(s.message(), "test-plugin: component type 'bad_path': param 'gain' is marked Path() but is double "
                         "(only string and list of strings can be paths)");
  EXPECT_EQ(catalog.Find("bad_path"), nullptr);
  EXPECT_NE(catalog.Find("good_path"), nullptr);
}

// Secret() is for strings only: the redaction replaces a value standing whole in the graph's
// text, and a number or a list has no such value to hide.
class ListMarkedAsSecret final : public Component {
 public:
  static void Describe(ComponentSpec& spec) { spec.Param("keys", std::vector<std::string>{}).Secret(); }
  Status Configure(Context&) override { return Status::OK(); }
  Status Step(const StepInfo&) override { return Status::OK(); }
};

TEST(Catalog, SecretOnANonStringParamIsRefused) {
  Catalog catalog;
  const Status s = catalog.Register("test-plugin", [](PluginRegistry& r) { r.Add<ListMarkedAsSecret>("bad_secret"); });
  EXPECT_EQ(s.code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(s.message(), "test-plugin: component type 'bad_secret': param 'keys' is marked Secret() but is list of string "
                         "(only a string can be a secret)");
  EXPECT_EQ(catalog.Find("bad_secret"), nullptr);
}

}  // namespace
}  // namespace dyad
