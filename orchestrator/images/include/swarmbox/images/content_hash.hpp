// SHA-256 of bytes as lower-case hex (OpenSSL EVP). Pure and thread-safe.
//
//   Sha256Hex("abc") == "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
#pragma once

#include <string>
#include <string_view>

namespace swarmbox::images {

std::string Sha256Hex(std::string_view bytes);

}  // namespace swarmbox::images
