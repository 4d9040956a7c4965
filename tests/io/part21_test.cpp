// STEP and IFC files cut short: found by their missing end, never mistaken for whole.
#include "lodforge/io/part21.h"

#include <gtest/gtest.h>

#include "test_support.h"

namespace lodforge {
namespace {

const std::string kWhole =
    "ISO-10303-21;\nHEADER;\nFILE_NAME('a','',(''),(''),'','','');\nENDSEC;\nDATA;\n"
    "#1=IFCPROJECT('x',$,'p',$,$,$,$,$,$);\n#12 = IFCWALL('y',$,$,$,$,$,$,$);\nENDSEC;\n"
    "END-ISO-10303-21;\n";

TEST(Part21, AWholeFileHasNoCutWhateverFollowsItsEnd) {
  test::TempDir dir;
  for (const std::string& tail :
       {std::string(), std::string("\n\n  \t"), std::string("/* written by x */\n")}) {
    test::writeFile(dir.file("a.ifc"), kWhole + tail);
    Result<std::optional<Part21Cut>> cut = findPart21Cut(dir.file("a.ifc"));
    ASSERT_TRUE(cut.ok()) << cut.error().message;
    EXPECT_FALSE(cut->has_value()) << tail;
  }
  // Not an exchange structure at all (an IFC-XML, an empty file): its reader judges it.
  test::writeFile(dir.file("x.ifc"), "<?xml version=\"1.0\"?><ifcXML/>");
  test::writeFile(dir.file("e.ifc"), "");
  EXPECT_FALSE(findPart21Cut(dir.file("x.ifc"))->has_value());
  EXPECT_FALSE(findPart21Cut(dir.file("e.ifc"))->has_value());
  EXPECT_FALSE(findPart21Cut(dir.file("missing.ifc")).ok());
}

TEST(Part21, ACutFileIsBadInputAtItsEndOrAWarningWithSalvage) {
  test::TempDir dir;
  const std::string cut = kWhole.substr(0, kWhole.find("#12") + 10);
  test::writeFile(dir.file("c.ifc"), cut);
  Result<std::optional<Part21Cut>> found = findPart21Cut(dir.file("c.ifc"));
  ASSERT_TRUE(found.ok() && found->has_value());
  EXPECT_EQ((*found)->bytes, cut.size());
  EXPECT_EQ((*found)->lastEntity, "#12");
  const Status refused = checkPart21Whole(dir.file("c.ifc"), false, nullptr);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().kind, ErrorKind::kBadInput);
  EXPECT_NE(refused.error().message.find(fmt::format("c.ifc: byte {}: the file ends here, inside "
                                                     "entity #12 without END-ISO-10303-21;",
                                                     cut.size())),
            std::string::npos)
      << refused.error().message;
  std::vector<std::string> warnings;
  ASSERT_TRUE(checkPart21Whole(dir.file("c.ifc"), true, &warnings).ok());
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("cut short at byte"), std::string::npos) << warnings[0];
}

}  // namespace
}  // namespace lodforge
