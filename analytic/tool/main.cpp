// analytic: evaluate the paper's closed-form shaders, and measure their approximations.
#include "eval_case.h"
#include "sweep.h"

#include "pine/support/tool_main.h"

#include <iostream>

int main(int argc, char** argv)
{
    CLI::App app{"Meyer & Neyret multiscale pine shaders: closed forms (levels 1-3) and their "
                 "measured approximations.\nSee docs/analytic-tool.md for the case keys."};
    app.require_subcommand(1);

    auto* eval = app.add_subcommand(
        "eval", "Read JSON Lines cases on stdin, write one JSON object of outputs per line");

    pine::analytic::tool::SweepOptions sweep;
    auto* sweepCmd = app.add_subcommand(
        "sweep", "Measure the F fit, the cone fits and the linear law; write CSV, summary.json "
                 "and sweep.png");
    sweepCmd->add_option("--out", sweep.outDir, "Output folder (created if missing)")->required();
    sweepCmd->add_option("--cone-cases", sweep.coneCases, "Random cases for the cone fits")
        ->capture_default_str()
        ->check(pine::tool::wholeNumberIn(10, 1000000));
    sweepCmd->add_option("--seed", sweep.seed, "Seed of the random cases")->capture_default_str();
    sweepCmd->add_flag("!--no-plot", sweep.plot, "Skip the plot (CSV and JSON only)");

    return pine::tool::run("analytic", app, argc, argv, [&] {
        if (*eval) return pine::analytic::tool::runEval(std::cin, std::cout, std::cerr);
        return pine::analytic::tool::runSweep(sweep);
    });
}
