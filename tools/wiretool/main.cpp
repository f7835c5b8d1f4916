// wiretool: the command-line front end of the wire runtime (mesh, bend, bench, view).
#include "commands.hpp"

#include <cstdio>
#include <vector>

int main(int argc, char** argv) {
    CLI::App app{"wiretool: wire meshes, bent environment meshes, benchmarks and the runtime's view of a wire file from the command line.\n"
                 "Exit status: 0 success, 1 an output could not be written, 2 bad input or usage."};
    app.require_subcommand(1);
    std::vector<std::pair<CLI::App*, wiretool::Action>> commands;
    auto add = [&](auto&& registrar) {
        const std::size_t before = app.get_subcommands({}).size();
        wiretool::Action action = registrar(app);
        commands.emplace_back(app.get_subcommands({})[before], std::move(action));
    };
    add(wiretool::add_mesh_command);
    add(wiretool::add_bend_command);
    add(wiretool::add_bench_command);
    add(wiretool::add_view_command);

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        app.exit(e);  // prints the message and usage
        return wiretool::exit_bad_input;
    }
    for (auto& [sub, action] : commands)
        if (sub->parsed()) return action();
    return wiretool::exit_bad_input;
}
