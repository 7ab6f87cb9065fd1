// The L-system's rewriting: parallel, copying symbols without a rule, bounded.
#include "pine/scenes/lsystem.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace pine::scenes {
namespace {

TEST(LSystem, RewritesInParallel)
{
    // Lindenmayer's algae: A -> AB, B -> A; lengths follow Fibonacci.
    const std::map<char, std::string> algae = {{'A', "AB"}, {'B', "A"}};
    EXPECT_EQ(expandLSystem("A", algae, 0), "A");
    EXPECT_EQ(expandLSystem("A", algae, 1), "AB");
    EXPECT_EQ(expandLSystem("A", algae, 2), "ABA");
    EXPECT_EQ(expandLSystem("A", algae, 4), "ABAABABA");
    // Symbols without a rule (F, brackets, turns) are copied.
    EXPECT_EQ(expandLSystem("A", {{'A', "F[+A]"}}, 2), "F[+F[+A]]");
}

TEST(LSystem, LengthWithoutExpandingMatchesTheExpansion)
{
    const std::map<char, std::string> fir = {
        {'A', "FFF[&B]/[&B]/[&B]/[&B]/[&B]/[&B]/!A"}, {'B', "F[+!C][-!C]B"}, {'C', "FC"}};
    for (int n = 0; n <= 6; ++n) {
        EXPECT_EQ(expandedLength("A", fir, n), expandLSystem("A", fir, n).size()) << n;
    }
}

TEST(LSystem, RunawayGrowthStopsAtTheLimit)
{
    const std::map<char, std::string> doubling = {{'A', "AA"}};
    EXPECT_EQ(expandedLength("A", doubling, 10, 5000), 1024u);
    EXPECT_EQ(expandedLength("A", doubling, 200, 5000), 5001u);  // saturates, no overflow
    EXPECT_THROW(expandLSystem("A", doubling, 13, 5000), std::length_error);
}

TEST(LSystem, Alphabet)
{
    for (char c : std::string("F[]+-&^/\\!")) EXPECT_TRUE(isTurtleSymbol(c)) << c;
    EXPECT_FALSE(isTurtleSymbol('A'));
    EXPECT_TRUE(isLSystemSymbol('A'));
    EXPECT_TRUE(isLSystemSymbol('z'));
    EXPECT_FALSE(isLSystemSymbol('$'));
    EXPECT_FALSE(isLSystemSymbol(' '));
    EXPECT_FALSE(isLSystemSymbol('1'));
}

}  // namespace
}  // namespace pine::scenes
