# Turns text files into a C++ source defining sdfc::embeddedSource(name), so
# the shader kernel ships inside the binary and stays editable as .glsl.
# Usage: cmake -DOUT=file.cpp -DFILES="name1=path1;name2=path2" -P embed_files.cmake
set(body "#include \"emit/embedded_sources.h\"\n#include <string_view>\nnamespace sdfc {\nnamespace {\n")
set(table "")
set(i 0)
foreach(entry IN LISTS FILES)
  string(REPLACE "=" ";" parts "${entry}")
  list(GET parts 0 name)
  list(GET parts 1 path)
  file(READ "${path}" content HEX)
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," content "${content}")
  string(APPEND body "const char kFile${i}[] = {${content}0};\n")
  string(APPEND table "  if (name == \"${name}\") return {kFile${i}, sizeof(kFile${i}) - 1};\n")
  math(EXPR i "${i} + 1")
endforeach()
string(APPEND body "}  // namespace\nstd::string_view embeddedSource(std::string_view name) {\n${table}  return {};\n}\n}  // namespace sdfc\n")
file(WRITE "${OUT}.new" "${body}")
file(COPY_FILE "${OUT}.new" "${OUT}" ONLY_IF_DIFFERENT)
