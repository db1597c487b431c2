/// `balloon materials list|show|delete|put`: the material library (presets and your own).
#include <google/protobuf/util/json_util.h>

#include <cstdio>
#include <iostream>

#include "arg_parser.hpp"
#include "cli_output.hpp"
#include "commands.hpp"
#include "exit_codes.hpp"
#include "field_flags.hpp"
#include "pressure_fall_line.hpp"
#include "service_connection.hpp"

namespace balloon::cli {
namespace {

namespace v1 = balloon::v1;

constexpr const char* HELP =
    "Usage: balloon materials list [--json]\n"
    "       balloon materials show NAME [--json]\n"
    "       balloon materials delete NAME\n"
    "       balloon materials put NAME --spec SPEC [--description TEXT] [--json]\n\n"
    "Presets (silicone, latex) are readable by all and cannot be deleted or replaced. SPEC as for\n"
    "--material, e.g. hart-smith:G=0.1,k1=3e-4,k2=1.0 (moduli in MPa).\n\n"
    "Exit codes: 0 ok, 2 bad input, 4 no such material, 5 unreachable, 6 not allowed (presets).\n\n";

void print_material(const v1::Material& material) {
  std::printf("%-16s %s%s\n", material.name().c_str(), material.spec().c_str(), material.preset() ? "  (preset)" : "");
  if (!material.description().empty()) std::printf("%-16s %s\n", "", material.description().c_str());
  if (material.has_pressure_fall())
    std::printf("%-16s its sphere pressure falls as it stretches %s\n", "",
                pressure_fall_range(material.pressure_fall()).c_str());
}

}  // namespace

int run_materials_command(const std::vector<std::string>& args, const GlobalOptions& global) {
  if (args.empty() || global.help) {
    std::fputs(HELP, stdout);
    std::fputs(global_options_help(), stdout);
    return args.empty() && !global.help ? EXIT_BAD_INPUT : EXIT_OK;
  }
  const std::string action = args.front();
  const std::string command = "materials " + action;
  Result<ParsedArgs> parsed = parse_args({args.begin() + 1, args.end()}, {{"spec"}, {"description"}});
  if (!parsed) return report_error(command, parsed.error(), EXIT_BAD_INPUT);
  if (action != "list" && action != "show" && action != "delete" && action != "put")
    return report_error("materials", "unknown action '" + action + "' (list, show, delete, put)", EXIT_BAD_INPUT);
  const bool needs_name = action != "list";
  if (needs_name && parsed->positionals.size() != 1) return report_error(command, "expected one material NAME", EXIT_BAD_INPUT);
  if (!needs_name && !parsed->positionals.empty())
    return report_error(command, "unexpected argument '" + parsed->positionals.front() + "'", EXIT_BAD_INPUT);
  if (action == "put" && !parsed->get("spec")) return report_error(command, "missing --spec SPEC", EXIT_BAD_INPUT);

  ConnectionOptions connection_opts = global.connection;
  connection_opts.run_jobs = false;
  auto connection = ServiceConnection::open(connection_opts);
  if (!connection) return report_error(command, connection.error(), EXIT_UNAVAILABLE);
  ServiceConnection& service = **connection;
  grpc::ClientContext context;
  service.prepare(context);
  const bool json = global.json;

  if (action == "list") {
    v1::ListMaterialsResponse reply;
    const grpc::Status status = service.stub().ListMaterials(&context, v1::ListMaterialsRequest(), &reply);
    if (!status.ok()) return report_error(command, status.error_message(), exit_code_for(status));
    if (json)
      std::cout << message_to_json(reply) << std::endl;
    else
      for (const v1::Material& material : reply.materials()) print_material(material);
    return EXIT_OK;
  }
  const std::string name = parsed->positionals.front();
  if (action == "delete") {
    v1::DeleteMaterialRequest request;
    request.set_name(name);
    v1::DeleteMaterialResponse reply;
    const grpc::Status status = service.stub().DeleteMaterial(&context, request, &reply);
    if (!status.ok()) return report_error(command, status.error_message(), exit_code_for(status));
    if (!json) std::printf("deleted %s\n", name.c_str());
    return EXIT_OK;
  }
  v1::Material material;
  grpc::Status status;
  if (action == "show") {
    v1::GetMaterialRequest request;
    request.set_name(name);
    status = service.stub().GetMaterial(&context, request, &material);
  } else {
    v1::PutMaterialRequest request;
    request.mutable_material()->set_name(name);
    request.mutable_material()->set_spec(*parsed->get("spec"));
    request.mutable_material()->set_description(parsed->get("description").value_or(""));
    status = service.stub().PutMaterial(&context, request, &material);
  }
  if (!status.ok()) return report_error(command, message_naming_fields(status), exit_code_for(status));
  if (json)
    std::cout << message_to_json(material) << std::endl;
  else
    print_material(material);
  return EXIT_OK;
}

}  // namespace balloon::cli
