// The temporary files being written right now (write_file_atomic, save_mesh), so that a
// signal handler can remove them: an interrupted write leaves neither a half-written
// output nor a stray temporary file. See pomar::remove_temporary_files_on_signals().
#pragma once

#include <string>

namespace pomar {

/// Remember `path` until unregister_temporary(); returns a slot (or -1 if the path is too
/// long or every slot is taken: the file is then just not removed on a signal).
int register_temporary(const std::string &path);
void unregister_temporary(int slot);

} // namespace pomar
