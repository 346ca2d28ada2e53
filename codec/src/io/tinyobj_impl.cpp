// tinyobjloader's implementation, compiled here from Debian's header rather than linked from
// Debian's libtinyobjloader.so: the OBJ parser then gets this build's flags (ASan, UBSan and
// the fuzzers' coverage instrument every byte it reads of a file), and there is no
// uninstrumented shared library between a file's bytes and our code.
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>
