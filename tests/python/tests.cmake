# The Python module's tests (pytest, tests/python/), one CTest test per file, run by the
# interpreter the module is built for (HILLDEM_PYTHON, Debian's /usr/bin/python3) against the build
# tree's module (PYTHONPATH), not an installed copy; included from tests/CMakeLists.txt. pytest's exit
# status 5 (no tests collected) fails a test like any other non-zero status.
file(GLOB HILLDEM_PYTESTS CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/python/test_*.py)
foreach(f IN LISTS HILLDEM_PYTESTS)
  get_filename_component(name ${f} NAME_WE)
  add_test(NAME python.${name} COMMAND ${HILLDEM_PYTHON} -m pytest -q -p no:cacheprovider ${f})
  set_tests_properties(python.${name} PROPERTIES TIMEOUT 600 LABELS python
    ENVIRONMENT "PYTHONPATH=${HILLDEM_PYTHON_DIR};HILLDEM_CLI=$<TARGET_FILE:hilldem>;HILLDEM_SOURCE_DIR=${PROJECT_SOURCE_DIR};PYTHONDONTWRITEBYTECODE=1;OMP_NUM_THREADS=1")
endforeach()
# The examples of examples/python/, each in its quick mode against the build tree's module, so that
# they cannot rot; figures and checkpoints go to <build>/python_examples.
file(GLOB HILLDEM_PY_EXAMPLES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/examples/python/*.py)
foreach(f IN LISTS HILLDEM_PY_EXAMPLES)
  get_filename_component(name ${f} NAME_WE)
  add_test(NAME python.example.${name} COMMAND ${HILLDEM_PYTHON} ${f} --quick --out ${CMAKE_BINARY_DIR}/python_examples/${name})
  set_tests_properties(python.example.${name} PROPERTIES TIMEOUT 300 LABELS python
    ENVIRONMENT "PYTHONPATH=${HILLDEM_PYTHON_DIR};PYTHONDONTWRITEBYTECODE=1;OMP_NUM_THREADS=1;MPLBACKEND=Agg")
endforeach()
