#include "lab/control_client.h"

#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {

ControlClient::ControlClient(const std::filesystem::path& path) : path_(path), socket_(io_) {
  std::error_code error;
  socket_.connect(asio::local::stream_protocol::endpoint(path.string()), error);
  if (error)
    throw Error(fmt::format("cannot connect to the server's control socket {}: {}", path.string(),
                            error.message()));
}

nlohmann::json ControlClient::ask_line(const std::string& line) {
  std::error_code error;
  asio::write(socket_, asio::buffer(line + "\n"), error);
  std::size_t size = 0;
  if (!error) size = asio::read_until(socket_, input_, '\n', error);
  if (error)
    throw Error(fmt::format("the server's control socket {}: {}", path_.string(), error.message()));
  const std::string reply(asio::buffers_begin(input_.data()),
                          asio::buffers_begin(input_.data()) + static_cast<std::ptrdiff_t>(size));
  input_.consume(size);
  nlohmann::json answer = nlohmann::json::parse(reply, nullptr, false);
  if (answer.is_discarded())
    throw Error(fmt::format("the server's control socket {} answered '{}'", path_.string(), reply));
  return answer;
}

nlohmann::json ControlClient::obey(const nlohmann::json& command) {
  nlohmann::json answer = ask(command);
  if (answer.contains("error"))
    throw Error(fmt::format("the server refused {}: {}", command.dump(),
                            answer["error"].get<std::string>()));
  return answer;
}

nlohmann::json ControlClient::serve(const std::string& name) { return obey({{"serve", name}}); }

nlohmann::json ControlClient::serve_next() { return obey({{"serve_next", true}}); }

}  // namespace cohaptic
