// What a Character handle shares: the loaded pack (mapped, validated; the
// fuzzy trees stay in the mapping).
#pragma once

#include <memory>
#include <string>

#include "character/pack.h"
#include "sinew/character.h"

namespace sinew::api {

struct Character::Impl {
  explicit Impl(character::Pack p) : pack(std::move(p)) {}
  character::Pack pack;
  std::string name;

  const character::Model& model() const { return pack.model(); }
};

// The one place that makes Character handles and reads their shared core.
struct CharacterFactory {
  static Result<Character> make(character::Pack pack, std::string name);
  static std::shared_ptr<const Character::Impl> share(const Character& c) { return c.impl_; }
};

}  // namespace sinew::api
