// patchcull: command-line entry point. With no arguments it runs the main job on the built-in
// default scene. Every error is one line on stderr and exit status 2.
#include <iostream>

#include "commands.h"
#include "patchcull/error.h"

int main(int argc, char** argv) {
    using namespace patchcull::cli;
    CLI::App app{"patchcull: conservative culling of bicubic patches before hardware tessellation"};
    app.require_subcommand(0, 1);
    const Runner info = add_info_command(app);
    const Runner cull = add_cull_command(app);
    const Runner demo = add_demo_command(app);
    try {
        app.parse(argc, argv);
        if (app.got_subcommand("info")) return info();
        if (app.got_subcommand("cull")) return cull();
        return demo();
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << "patchcull: error: " << e.what() << "\n";
        return 2;
    } catch (const patchcull::Error& e) {
        std::cerr << "patchcull: error: " << e.what() << "\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "patchcull: internal error: " << e.what() << "\n";
        return 3;
    }
}
