#include <doctest/doctest.h>

#include <nlohmann/json.hpp>
#include <simsr/nn/network_config.hpp>

#include "../support/error_of.hpp"

using namespace simsr;
using nlohmann::json;

TEST_CASE("nn::NetworkConfig::with_fields: the preset with each field given, every other field the preset's") {
  const json fields = {{"knn", 3}, {"upK", 4}, {"residual", true}, {"lr", 1e-3}, {"zreg", "ramped_norm"}, {"decoder_dims", {227, 64, 3}}};
  for (const std::string preset : {"official", "paper"}) {
    const nn::NetworkConfig c = nn::NetworkConfig::with_fields(preset, fields);
    const json got = c.to_json(), base = nn::NetworkConfig::preset(preset).to_json();
    for (const auto& item : got.items()) {
      // named copies, not a structured binding: clang 14 cannot capture a binding in doctest's lambdas
      const std::string key = item.key();
      const json& value = item.value();
      if (fields.contains(key))
        CHECK_MESSAGE(value == fields.at(key), key);
      else if (key != "decoder_dim")  // config.py's shorthand, derived from decoder_dims
        CHECK_MESSAGE(value == base.at(key), key);
    }
    CHECK(c.profile == preset);
  }
  CHECK(nn::NetworkConfig::with_fields("official", json::object()).to_json() == nn::NetworkConfig::official().to_json());
}

TEST_CASE("nn::NetworkConfig::with_fields: unknown fields, shorthands that would not hold and bad values are refused by name") {
  using test::typed_error_of;
  auto refuse = [](const json& fields) { return typed_error_of<ArgumentError>([&] { nn::NetworkConfig::with_fields("official", fields); }); };
  CHECK(refuse({{"kmn", 3}}) == "nn::NetworkConfig: unknown field 'kmn'");
  // from_json would take decoder_dims over decoder_dim silently; here the dropped field is named
  CHECK(refuse({{"decoder_dim", 64}}).find("field 'decoder_dim' = 64 does not hold") != std::string::npos);
  CHECK(refuse({{"profile", "paper"}}).find("'profile' is the preset") != std::string::npos);
  CHECK(refuse({{"knn", "five"}}).find("key 'knn'") != std::string::npos);
  CHECK(refuse({{"zreg", "l3"}}).find("zreg") != std::string::npos);
  CHECK(refuse({{"knn", -2}}).find("knn") != std::string::npos);  // validate()'s range check
  CHECK(typed_error_of<ArgumentError>([] { nn::NetworkConfig::with_fields("fast", json::object()); }).find("unknown profile 'fast'") !=
        std::string::npos);
  CHECK(typed_error_of<ArgumentError>([] { nn::NetworkConfig::with_fields("official", json::array()); }) ==
        "nn::NetworkConfig: the fields are not a JSON object");
}
