# Message types from OMG IDL, for dyad itself and for plugins that bring their own.
#
# dyad_add_messages(<target> NAMESPACE <ns> FILES <a.idl>... [IDL_DIR <dir>] [INCLUDE_PREFIX <dir>])
#
#   Compiles the IDL files (IDL_DIR, default the calling folder) into <target>: runs fastddsgen at
#   build time with dyad's IDL folder on the include path, so `#include "header.idl"` and a member
#   `dyad::msg::Header header;` reuse dyad's Header (its code lives in dyad::msgs; the copy
#   fastddsgen writes for included files is discarded), generates the type traits (below) into
#   <INCLUDE_PREFIX>/types.hpp (default <target>/msg/types.hpp), and links <target> to dyad::msgs.
#   (its Fast DDS type supports in types_support.hpp, which only code that instantiates a
#   PubSubType itself needs, and types_support.cpp, compiled into <target>).
#   In the plugin: `#include <<target>/msg/types.hpp>` and use `ns::Struct` as a port type; the
#   runtime, `dyad echo/hz` (with --graph or --plugins), the recorder and `dyad bag export` then
#   know the type, its IDL travelling with it. Example: tests/out_of_tree/messages/.
#
#   Each struct must start with `dyad::msg::Header header;` (the runtime stamps it).
#
# dyad_add_messages(<target> ROS2 FILES <pkg>/msg/<Type>.idl... [IDL_DIR <dir>])
#
#   More ROS 2 message types (docs/ros2.md), laid out as dyad's idl/ros2/: each file holds struct
#   <Type>_ in module <pkg>::msg::dds_ and may include dyad's ROS 2 types
#   (`#include "std_msgs/msg/Header.idl"`: their code lives in dyad::msgs). Headers land as
#   <pkg>/msg/<Type>.h, the traits as <target>/msg/types.hpp (INCLUDE_PREFIX), the types named
#   by their ROS 2 names, with no dyad Header and no hash on the wire. Example:
#   tests/out_of_tree/ros2_messages/.
#
# Needs DYAD_IDL_DIR (dyad's IDL files) and DYAD_MSG_INCLUDE_DIR (the folder holding dyad's
# generated header.h): find_package(dyad) sets both; dyad's own build sets them in idl/.

find_program(FASTDDSGEN fastddsgen)

function(dyad_add_messages target)
  cmake_parse_arguments(A "ROS2" "NAMESPACE;IDL_DIR;INCLUDE_PREFIX" "FILES" ${ARGN})
  if(A_ROS2 AND NOT A_NAMESPACE)
    set(A_NAMESPACE ${target}::ros2)  # holds only AllTypes()
  endif()
  if(NOT A_NAMESPACE OR NOT A_FILES)
    message(FATAL_ERROR "dyad_add_messages(${target}): NAMESPACE and FILES are required")
  endif()
  if(NOT FASTDDSGEN)
    message(FATAL_ERROR "dyad_add_messages(${target}): fastddsgen not found (Debian package fastddsgen, with a Java runtime)")
  endif()
  if(NOT A_IDL_DIR)
    set(A_IDL_DIR ${CMAKE_CURRENT_SOURCE_DIR})
  endif()
  if(NOT A_INCLUDE_PREFIX)
    set(A_INCLUDE_PREFIX ${target}/msg)
  endif()
  set(_root ${CMAKE_CURRENT_BINARY_DIR}/dyad_messages/${target})
  set(_out ${_root}/include/${A_INCLUDE_PREFIX})
  set(_scratch ${_root}/fastddsgen)
  set(_idl_paths "")
  set(_outputs "")
  set(_own_files "")
  set(_copies "")
  set(_dest_dirs ${_out})
  foreach(_idl IN LISTS A_FILES)
    get_filename_component(_stem ${_idl} NAME_WE)
    list(APPEND _idl_paths ${A_IDL_DIR}/${_idl})
    # A ROS 2 type's C++ goes where its generated includes look for it: <pkg>/msg/.
    set(_dest ${_out})
    if(A_ROS2)
      get_filename_component(_pkg_dir ${_idl} DIRECTORY)
      set(_dest ${_root}/include/${_pkg_dir})
      list(APPEND _dest_dirs ${_dest})
    endif()
    foreach(_suffix .h .cxx PubSubTypes.h PubSubTypes.cxx)
      list(APPEND _copies COMMAND ${CMAKE_COMMAND} -E copy ${_scratch}/${_stem}${_suffix} ${_dest}/${_stem}${_suffix})
      list(APPEND _outputs ${_dest}/${_stem}${_suffix})
    endforeach()
  endforeach()
  set(_include_path -I ${A_IDL_DIR} -I ${DYAD_IDL_DIR})
  set(_traits_path ${DYAD_IDL_DIR})
  if(A_ROS2)
    set(_include_path -I ${A_IDL_DIR} -I ${DYAD_IDL_DIR}/ros2)
    set(_traits_path ${DYAD_IDL_DIR}/ros2)
    set(_traits_mode ROS2)
  endif()
  # fastddsgen also writes C++ for every included file (a second dyad::msg::Header): it goes to a
  # scratch folder, and only the files of FILES are kept. -t: its preprocessed files go to a
  # folder of this call's, not /tmp, where another build's fastddsgen would overwrite them.
  add_custom_command(
    OUTPUT ${_outputs}
    COMMAND ${CMAKE_COMMAND} -E rm -rf ${_scratch}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${_scratch} ${_scratch}_tmp ${_dest_dirs}
    COMMAND ${FASTDDSGEN} -cs -replace -t ${_scratch}_tmp -d ${_scratch} ${_include_path} ${_idl_paths}
    ${_copies}
    DEPENDS ${_idl_paths}
    WORKING_DIRECTORY ${A_IDL_DIR}
    COMMENT "fastddsgen: C++ for ${A_FILES} (${target})"
    VERBATIM)
  dyad_generate_type_traits(
    OUTPUT ${_out}/types.hpp
    NAMESPACE ${A_NAMESPACE}
    INCLUDE_PREFIX ${A_INCLUDE_PREFIX}
    IDL_DIR ${A_IDL_DIR}
    IDL_PATH ${_traits_path}
    ${_traits_mode}
    FILES ${A_FILES})
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${_idl_paths})
  set(_sources ${_outputs})
  list(FILTER _sources INCLUDE REGEX "\\.cxx$")
  target_sources(${target} PRIVATE ${_sources} ${_out}/types_support.cpp)
  set_source_files_properties(${_sources} PROPERTIES COMPILE_OPTIONS -w)  # fastddsgen's code is not ours to fix
  # ${_out}: our generated "x.h" includes; DYAD_MSG_INCLUDE_DIR: their "header.h"; two levels up
  # from it (gen/ in dyad's build, include/ installed): dyad's ROS 2 headers, "std_msgs/msg/Header.h".
  get_filename_component(_ros2_include "${DYAD_MSG_INCLUDE_DIR}/../.." ABSOLUTE)
  target_include_directories(${target} PRIVATE ${_root}/include ${_out} ${DYAD_MSG_INCLUDE_DIR} ${_ros2_include})
  if(TARGET dyad::msgs)
    target_link_libraries(${target} PRIVATE dyad::msgs)
  else()
    target_link_libraries(${target} PRIVATE dyad_msgs)
  endif()
endfunction()

# dyad_generate_type_traits(OUTPUT file NAMESPACE ns INCLUDE_PREFIX dir IDL_DIR dir [IDL_PATH dir...] FILES a.idl ...)
#
# Writes a header that includes fastddsgen's output for FILES and declares, for every struct,
# dyad::MessageTraits<ns::Struct> (see dyad/message_traits.hpp): the DDS type name
# "<ns>::<Struct>#<hash>", where hash covers the definition text of the file and of the files it
# includes with comments and whitespace removed, and the IDL text itself (includes inlined) as
# the schema a recording carries. `#include "x.idl"` is looked up in IDL_DIR, then IDL_PATH.
# dyad_add_messages calls it; use it directly only with fastddsgen output of your own.
#
# ROS2: FILES are ROS 2 message types laid out as <pkg>/msg/<Type>.idl, each holding struct
# <Type>_ in module <pkg>::msg::dds_ (ROS 2's wire names); their headers are included as
# <pkg>/msg/<Type>.h, their traits name them by their ROS 2 name "<pkg>/msg/<Type>" too, and
# their DDS type name is the plain IDL name (no hash: ROS 2 peers match on it). NAMESPACE then
# only holds AllTypes(). They carry no dyad Header: the runtime stamps nothing in them.
function(dyad_generate_type_traits)
  cmake_parse_arguments(A "ROS2" "OUTPUT;NAMESPACE;INCLUDE_PREFIX;IDL_DIR" "FILES;IDL_PATH" ${ARGN})
  set(_body "")
  set(_list "")
  set(_includes "")
  set(_support_includes "")
  set(_forward "")
  set(_support_body "")
  foreach(_idl IN LISTS A_FILES)
    get_filename_component(_stem ${_idl} NAME_WE)
    _dyad_idl_inline("${A_IDL_DIR};${A_IDL_PATH}" ${_idl} _text)
    string(REGEX REPLACE "//[^\n]*" "" _normal "${_text}")
    string(REGEX REPLACE "/\\*([^*]|\\*[^/])*\\*/" "" _normal "${_normal}")
    string(REGEX REPLACE "[ \t\r\n]+" " " _normal "${_normal}")
    string(SHA256 _sha "${_normal}")
    string(SUBSTRING ${_sha} 0 16 _hash)
    if(A_ROS2)
      get_filename_component(_prefix ${_idl} DIRECTORY)
      string(REGEX REPLACE "/.*" "" _pkg ${_idl})
      set(_struct_ns ${_pkg}::msg::dds_)
    else()
      set(_prefix ${A_INCLUDE_PREFIX})
      set(_struct_ns ${A_NAMESPACE})
    endif()
    string(APPEND _includes "#include <${_prefix}/${_stem}.h>\n")
    string(APPEND _support_includes "#include <${_prefix}/${_stem}PubSubTypes.h>\n")
    # Only structs defined in this file itself get traits (not those of included files).
    file(READ ${A_IDL_DIR}/${_idl} _own)
    string(REGEX MATCHALL "struct[ \t\n]+[A-Za-z_][A-Za-z0-9_]*[ \t\n]*{" _structs "${_own}")
    foreach(_s IN LISTS _structs)
      string(REGEX REPLACE "struct[ \t\n]+([A-Za-z_][A-Za-z0-9_]*).*" "\\1" _name "${_s}")
      if(A_ROS2)
        string(REGEX REPLACE "_$" "" _ros_type ${_name})
        string(APPEND _body "DYAD_ROS2_MESSAGE_TYPE(${_struct_ns}, ${_name}, \"${_prefix}/${_ros_type}\", \"${_hash}\", R\"dyadidl(${_text})dyadidl\");\n")
      else()
        string(APPEND _body "DYAD_MESSAGE_TYPE(${_struct_ns}, ${_name}, \"${_hash}\", R\"dyadidl(${_text})dyadidl\");\n")
      endif()
      string(APPEND _list "      &::dyad::TypeInfoOf<${_struct_ns}::${_name}>(),\n")
      string(APPEND _forward "namespace ${_struct_ns} { class ${_name}PubSubType; }\n")
      string(APPEND _support_body "DYAD_MESSAGE_TYPE_SUPPORT(${_struct_ns}, ${_name})\n")
    endforeach()
  endforeach()
  # The traits need only the messages' own headers and forward declarations of their type
  # supports: fastddsgen's PubSubTypes headers pull in Fast DDS's TopicDataType, most of a file's
  # parse time (2.7 of 3.8 s here), in every file that uses a message. Those headers go to
  # <name>_support.hpp (for code that instantiates a PubSubType) and <name>_support.cpp (the
  # traits' MakeTypeSupport, compiled once into the messages' library).
  get_filename_component(_dir ${A_OUTPUT} DIRECTORY)
  get_filename_component(_base ${A_OUTPUT} NAME_WE)
  get_filename_component(_header ${A_OUTPUT} NAME)
  set(_content "// Generated by dyad_generate_type_traits from ${A_FILES}. Do not edit.\n#pragma once\n#include <vector>\n#include <dyad/message_traits.hpp>\n${_includes}\n${_forward}\n${_body}\nnamespace ${A_NAMESPACE} {\n// Every message type of these IDL files.\ninline std::vector<const ::dyad::TypeInfo*> AllTypes() {\n  return {\n${_list}  };\n}\n}  // namespace ${A_NAMESPACE}\n")
  _dyad_write_if_changed(${A_OUTPUT} "${_content}")
  _dyad_write_if_changed(${_dir}/${_base}_support.hpp
    "// Generated by dyad_generate_type_traits: the Fast DDS type supports of ${_header}. Do not edit.\n#pragma once\n#include \"${_header}\"\n${_support_includes}")
  _dyad_write_if_changed(${_dir}/${_base}_support.cpp
    "// Generated by dyad_generate_type_traits. Do not edit.\n#include \"${_base}_support.hpp\"\n\n${_support_body}")
endfunction()

function(_dyad_write_if_changed file content)
  set(_old "")
  if(EXISTS ${file})
    file(READ ${file} _old)
  endif()
  if(NOT "${_old}" STREQUAL "${content}")
    file(WRITE ${file} "${content}")
  endif()
endfunction()

# The IDL text of `file` (found in the first of `dirs` that has it) with its #include "x.idl"
# lines replaced by x.idl's text, each file once (ROS 2 types include Header along several paths).
function(_dyad_idl_inline dirs file out)
  set_property(GLOBAL PROPERTY _DYAD_IDL_INLINED "")
  _dyad_idl_inline_once("${dirs}" ${file} _text)
  set(${out} "${_text}" PARENT_SCOPE)
endfunction()

function(_dyad_idl_inline_once dirs file out)
  get_property(_done GLOBAL PROPERTY _DYAD_IDL_INLINED)
  if(file IN_LIST _done)
    set(${out} "" PARENT_SCOPE)
    return()
  endif()
  set_property(GLOBAL APPEND PROPERTY _DYAD_IDL_INLINED ${file})
  set(_path "")
  foreach(_dir IN LISTS dirs)
    if(_dir AND EXISTS ${_dir}/${file} AND NOT _path)
      set(_path ${_dir}/${file})
    endif()
  endforeach()
  if(NOT _path)
    message(FATAL_ERROR "IDL file ${file} not found in: ${dirs}")
  endif()
  file(READ ${_path} _text)
  string(REGEX MATCHALL "#include[ \t]+\"[^\"]+\"" _incs "${_text}")
  foreach(_inc IN LISTS _incs)
    string(REGEX REPLACE "#include[ \t]+\"([^\"]+)\"" "\\1" _inc_file "${_inc}")
    _dyad_idl_inline_once("${dirs}" ${_inc_file} _inc_text)
    string(REPLACE "${_inc}" "${_inc_text}" _text "${_text}")
  endforeach()
  set(${out} "${_text}" PARENT_SCOPE)
endfunction()
