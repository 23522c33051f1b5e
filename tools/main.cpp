// patchcull: command-line entry point. With no arguments it runs the main job on the built-in
// default scene (tools/cmd_demo.cpp). Every error is one line on stderr and exit status 2 (a
// missing OpenGL driver included: GlContext::create_headless throws patchcull::Error). Messages go
// through printable_line as a last line of defence: whatever a flag, path or library put in them,
// the user sees one printable line of bounded length.
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "cli_options.h"
#include "commands.h"
#include "patchcull/core/error.h"
#include "patchcull/version.h"

namespace {

int run_cli(int argc, char** argv) {
    using namespace patchcull::cli;
    CLI::App app{"patchcull: conservative culling of bicubic patches before hardware tessellation"};
    app.require_subcommand(0, 1);
    // "patchcull 0.1.0" on stdout, exit 0: the linked library's version, not the header's.
    app.set_version_flag("--version", std::string("patchcull ") + patchcull::version_string(),
                         "Print the version and exit");
    const Runner info = add_info_command(app);
    const Runner cull = add_cull_command(app);
    const Runner render = add_render_command(app);
    const Runner view = add_view_command(app);
    const Runner eval = add_eval_command(app);
    const Runner demo = add_demo_command(app);
    try {
        app.parse(argc, argv);
        if (app.got_subcommand("info")) return info();
        if (app.got_subcommand("cull")) return cull();
        if (app.got_subcommand("render")) return render();
        if (app.got_subcommand("view")) return view();
        if (app.got_subcommand("eval")) return eval();
        return demo();  // `demo`, or no subcommand: the main job with its default options
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << "patchcull: error: " << patchcull::printable_line(parse_error_message(e)) << "\n";
        return 2;
    } catch (const patchcull::Error& e) {
        std::cerr << "patchcull: error: " << patchcull::printable_line(e.what()) << "\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "patchcull: internal error: " << patchcull::printable_line(e.what()) << "\n";
        return 3;
    }
}

}  // namespace

// Whatever escapes the commands' own handling (building the parser included) is still one line.
int main(int argc, char** argv) {
    try {
        return run_cli(argc, argv);
    } catch (const std::exception& e) {
        std::cerr << "patchcull: internal error: " << patchcull::printable_line(e.what()) << "\n";
    } catch (...) {
        std::cerr << "patchcull: internal error: an unknown exception\n";
    }
    return 3;
}
