// Files from the source tree's docker/rootfs/ compiled into the library (generated
// base_files.cpp), so a deployed `swarmbox` needs no source tree to pack images.
#pragma once

namespace swarmbox::images::detail {

extern const char kEtcPasswd[];
extern const char kEtcGroup[];

}  // namespace swarmbox::images::detail
