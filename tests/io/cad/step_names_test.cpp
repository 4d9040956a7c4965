// A STEP file's strings that are not UTF-8, and the code page their bytes make clear.
#include "lodforge/io/cad/step_names.h"

#include <gtest/gtest.h>

namespace lodforge {
namespace {

TEST(StepNames, Utf8AndAsciiNamesNeedNoCodePage) {
  const StepStrings s = scanStepText(
      "#1=PRODUCT('Gehäuse','\xD0\x9A\xD1\x80\xD1\x8B\xD1\x88\xD0\xBA\xD0\xB0','it''s',(#2));\n"
      "/* 'not a string: \xFF' */ #2=PRODUCT('\\X2\\041A\\X0\\','','',());");
  EXPECT_EQ(s.strings, 6u);
  EXPECT_EQ(s.notUtf8, 0u);
  EXPECT_TRUE(s.guess.empty());
}

TEST(StepNames, CyrillicWordsAreCp1251AndAccentsAmongLatinCp1252) {
  // "Корпус насоса", "Крышка" in CP1251: whole words of high bytes.
  const StepStrings cyrillic = scanStepText(
      "#1=PRODUCT('\xCA\xEE\xF0\xEF\xF3\xF1 \xED\xE0\xF1\xEE\xF1\xE0','x','',());"
      "#2=PRODUCT('\xCA\xF0\xFB\xF8\xEA\xE0','','',());");
  EXPECT_EQ(cyrillic.notUtf8, 2u);
  EXPECT_EQ(cyrillic.guess, "CP1251");
  EXPECT_EQ(cyrillic.example, "\\xCA\\xEE\\xF0\\xEF\\xF3\\xF1 \\xED\\xE0\\xF1\\xEE\\xF1\\xE0");
  // "Pièce", "Größe" in CP1252: a letter or two among Latin ones.
  const StepStrings western = scanStepText(
      "#1=PRODUCT('Pi\xE8"
      "ce','Gr\xF6\xDF"
      "e','',());");
  EXPECT_EQ(western.notUtf8, 2u);
  EXPECT_EQ(western.guess, "CP1252");
  // Bytes no 8-bit code page makes clear (Shift-JIS lead and trail bytes): no guess.
  const StepStrings unclear = scanStepText("#1=PRODUCT('\x81\x41\x83\x7F\x90','','',());");
  EXPECT_EQ(unclear.notUtf8, 1u);
  EXPECT_TRUE(unclear.guess.empty());
}

}  // namespace
}  // namespace lodforge
