// `analytic eval`: its keys, its normalisation of input vectors and its one-line errors.
#include "eval_case.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

namespace pine::analytic::tool {
namespace {

const std::string kBough =
    R"({"level":"bough","axis":[0,0,1],"L":[1,0,0],"V":[0,1,0.2],"radius":0.05,"length":4.25,)"
    R"("aperture":0.3927,"needles_per_cone":12,"cone_spacing":0.9,"exponent":100})";

struct EvalRun {
    int status;
    std::string out, err;
};

EvalRun run(const std::string& input)
{
    std::istringstream in(input);
    std::ostringstream out, err;
    const int status = runEval(in, out, err);
    return {status, out.str(), err.str()};
}

TEST(EvalTool, WritesTheDocumentedKeysPerLevel)
{
    const EvalRun r = run(
        R"({"level":"needle","axis":[0,0,1],"L":[1,0,0],"V":[0,1,0],"exponent":50})" "\n"
        R"({"level":"cone","axis":[0,0,1],"L":[1,0,0],"V":[0,1,0],"radius":0.05,"length":4.25,"aperture":0.39,"needles_per_cone":12,"exponent":50})" "\n" +
        kBough + "\n");
    ASSERT_EQ(r.status, 0) << r.err;
    std::istringstream lines(r.out);
    std::string line;
    const std::vector<std::vector<std::string>> keys = {
        {"diffuse", "specular"},
        {"alpha_front", "alpha_rear", "diffuse_front", "diffuse_rear", "specular_front", "specular_rear"},
        {"A", "R", "k_V", "k_V_bar", "alpha_front", "alpha_rear", "alpha_front_exact",
         "alpha_rear_exact", "alpha_exact", "I_front", "I_rear"}};
    for (const auto& expected : keys) {
        ASSERT_TRUE(std::getline(lines, line));
        const auto j = nlohmann::json::parse(line);
        for (const auto& k : expected) {
            ASSERT_TRUE(j.contains(k)) << k;
            EXPECT_TRUE(j[k].is_number() && std::isfinite(j[k].get<double>())) << k;
        }
    }
}

TEST(EvalTool, VectorsNeedNotBeUnitLength)
{
    std::string scaled = kBough;
    scaled.replace(scaled.find(R"("V":[0,1,0.2])"), 13, R"("V":[0,5,1.0])");
    const EvalRun a = run(kBough + "\n"), b = run(scaled + "\n");
    ASSERT_EQ(a.status, 0);
    ASSERT_EQ(b.status, 0) << b.err;
    const auto ja = nlohmann::json::parse(a.out), jb = nlohmann::json::parse(b.out);
    for (const auto& [key, value] : ja.items()) {
        if (value.is_number()) {
            EXPECT_NEAR(value.get<double>(), jb[key].get<double>(), 1e-12) << key;
        }
    }
}

TEST(EvalTool, InfiniteLayerRateIsWrittenAsInf)
{
    std::string along = kBough;
    along.replace(along.find(R"("V":[0,1,0.2])"), 13, R"("V":[0,0,1]  )");
    const EvalRun r = run(along + "\n");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["k_V"], "inf");
    EXPECT_DOUBLE_EQ(j["alpha_exact"].get<double>(), 1.0);
}

struct BadLine {
    std::string line, key;
};

TEST(EvalTool, BadLinesNameLineAndKeyAndExitTwo)
{
    const std::vector<BadLine> cases = {
        {R"({"level":"needle","axis":[0,0,1],"L":[1,0,0],"V":[0,0,0],"exponent":5})", "V"},
        {R"({"level":"needle","axis":[0,0,1],"L":[1,0,0],"exponent":5})", "V"},
        {R"({"level":"needle","axis":[0,0,1],"L":[1,0,0],"V":[0,1,0],"exponent":1e999})", "exponent"},
        {R"({"level":"needle","axis":[0,0,1],"L":[1,0,"x"],"V":[0,1,0],"exponent":5})", "L"},
        {R"({"level":"needle","axis":[0,0,1],"L":[1,-1e999,0],"V":[0,1,0],"exponent":5})", "L"},
        {R"({"level":"needle","axis":[0,0,1],"L":[1,0,0],"V":[0,1,0],"exponent":5,"apperture":1})", "apperture"},
        // A key given twice: JSON keeps the last, which would hide the first's bad value.
        {R"({"level":"needle","axis":[0,0,1],"L":[1,0,0],"V":[0,1,0],"exponent":-5,"exponent":2})", "exponent"},
        {R"({"level":"leaf","axis":[0,0,1],"L":[1,0,0],"V":[0,1,0]})", "level"},
        {R"({"level":"cone","axis":[0,0,1],"L":[1,0,0],"V":[0,1,0],"radius":-0.05,"length":4,"aperture":0.4,"needles_per_cone":12,"exponent":50})", "radius"},
        {R"({"level":"cone","axis":[0,0,1],"L":[1,0,0],"V":[0,1,0],"radius":0.05,"length":4,"aperture":2.0,"needles_per_cone":12,"exponent":50})", "aperture"},
        {R"({"level":"bough","axis":[0,0,1],"L":[1,0,0],"V":[0,1,0],"radius":0.05,"length":4,"aperture":0.4,"needles_per_cone":12,"cone_spacing":0,"exponent":50})", "cone_spacing"},
    };
    for (const BadLine& c : cases) {
        const EvalRun r = run(kBough + "\n" + c.line + "\n" + kBough + "\n");
        EXPECT_EQ(r.status, 2) << c.line;
        EXPECT_NE(r.err.find("line 2"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("'" + c.key + "'"), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
        EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << "stops at the bad line";
    }
}

TEST(EvalTool, NotJsonIsReportedWithItsLine)
{
    const EvalRun r = run(kBough + "\n\n{level: needle}\n");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("line 3"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("not JSON"), std::string::npos) << r.err;
    // Two objects on a line: said once, in plain words (it read "parse error: [json.exception.
    // parse_error.101] parse error at ...").
    const EvalRun two = run(kBough + " " + kBough + "\n");
    EXPECT_EQ(two.status, 2);
    EXPECT_NE(two.err.find("line 1: not JSON (parse error at line 1, column "), std::string::npos)
        << two.err;
    EXPECT_EQ(two.err.find("json.exception"), std::string::npos) << two.err;
}

}  // namespace
}  // namespace pine::analytic::tool
