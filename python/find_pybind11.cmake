# Included by the top-level CMakeLists.txt: the interpreter for the Python bindings,
# then pybind11 (which builds for the Python found first). Sets pybind11_FOUND.
#
# The bindings return NumPy arrays, so the interpreter is the first python3 on PATH
# that imports numpy (a pyenv or a virtual environment without NumPy is passed
# over); -DPython3_EXECUTABLE=... chooses another.
if(NOT Python3_EXECUTABLE)
  string(REPLACE ":" ";" _cocone_path "$ENV{PATH}")
  foreach(_cocone_dir IN LISTS _cocone_path)
    if(_cocone_dir AND EXISTS "${_cocone_dir}/python3")
      execute_process(COMMAND "${_cocone_dir}/python3" -c "import numpy"
                      RESULT_VARIABLE _cocone_no_numpy OUTPUT_QUIET ERROR_QUIET)
      if(_cocone_no_numpy EQUAL 0)
        set(Python3_EXECUTABLE "${_cocone_dir}/python3" CACHE FILEPATH
            "The Python interpreter of the bindings")
        break()
      endif()
    endif()
  endforeach()
  unset(_cocone_path)
  unset(_cocone_dir)
  unset(_cocone_no_numpy)
endif()
find_package(Python3 COMPONENTS Interpreter Development.Module)
if(Python3_FOUND)
  find_package(pybind11 CONFIG QUIET)
endif()
if(NOT pybind11_FOUND)
  message(STATUS "pybind11 (or Python 3 with its headers) not found: no Python "
                 "bindings (COCONE_BUILD_PYTHON)")
endif()
