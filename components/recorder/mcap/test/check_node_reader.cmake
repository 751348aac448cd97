# CTest driver: C++ writes recordings, @mcap/core (Node) reads them back, every sample accounted for.
# Inputs: NODE (node executable or NOTFOUND), NODE_DIR (components/recorder/test/node),
# FIXTURE (dyad_mcap_write_fixture), WORK_DIR (scratch folder).
# Missing Node or node_modules is a failure, not a skip: the independent check must run in CI.
if(NOT NODE OR NOT EXISTS "${NODE}")
  message(FATAL_ERROR "node not found: install Node.js >= 18 (Debian: apt-get install nodejs) and re-run cmake")
endif()
if(NOT EXISTS "${NODE_DIR}/node_modules/@mcap/core/package.json" OR NOT EXISTS "${NODE_DIR}/node_modules/fzstd/package.json")
  message(FATAL_ERROR "${NODE_DIR}/node_modules is missing @mcap/core or fzstd: run `npm ci --prefix components/recorder/test/node` from the repository root")
endif()

file(REMOVE_RECURSE "${WORK_DIR}")
execute_process(COMMAND "${FIXTURE}" "${WORK_DIR}" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "dyad_mcap_write_fixture failed (${rc})")
endif()

# Runs read_mcap.mjs on NAME.mcap with extra ARGN options and compares with NAME.expected.json.
function(check_with_node name label)
  execute_process(
    COMMAND "${NODE}" "${NODE_DIR}/read_mcap.mjs" ${ARGN} --expect "${WORK_DIR}/${name}.expected.json" "${WORK_DIR}/${name}.mcap"
    OUTPUT_FILE "${WORK_DIR}/${name}.${label}.actual.json"
    RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "@mcap/core (${label} reader) disagrees with dyad_mcap on ${name}.mcap; its output: ${WORK_DIR}/${name}.${label}.actual.json")
  endif()
endfunction()

# The complete file through the indexed and the streaming reader; the cut file through the
# streaming reader (the indexed reader needs a footer).
check_with_node(full indexed)
check_with_node(full stream --stream)
check_with_node(cut stream --stream)
message(STATUS "@mcap/core read every sample of full.mcap (indexed and streaming) and of cut.mcap (streaming)")
