# Copyright 2026 active_recognition maintainers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

# Loaded into each package of interfaces/ by tools/build_interfaces.sh (CMAKE_PROJECT_INCLUDE), for
# a build against the PyPI ROS wheels only. Their exported CMake targets
# (<pkg>__rosidl_generator_py) name the include folders of the Python the wheels were built
# with (/opt/python/cp311-cp311/...), which exist on no user's machine, and CMake refuses an
# imported target with a missing include folder. At the end of the configure step, every
# imported target that names a missing folder gets it replaced by this build's Python and NumPy
# include folders. The wheels' files stay as they are.
cmake_minimum_required(VERSION 3.21)  # IMPORTED_TARGETS, cmake_language(DEFER)

function(active_recognition_use_this_python)
  find_package(Python3 REQUIRED COMPONENTS Interpreter Development.Module NumPy)
  get_directory_property(targets IMPORTED_TARGETS)
  foreach(target IN LISTS targets)
    get_target_property(dirs ${target} INTERFACE_INCLUDE_DIRECTORIES)
    if(NOT dirs)
      continue()
    endif()
    set(kept "")
    set(missing FALSE)
    foreach(dir IN LISTS dirs)
      if(dir MATCHES "^\\$<" OR EXISTS "${dir}")  # generator expressions are CMake's business
        list(APPEND kept "${dir}")
      else()
        set(missing TRUE)
      endif()
    endforeach()
    if(missing)
      list(APPEND kept ${Python3_INCLUDE_DIRS} ${Python3_NumPy_INCLUDE_DIRS})
      list(REMOVE_DUPLICATES kept)
      set_target_properties(${target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${kept}")
      message(STATUS "${target}: include folders of the wheels' build Python -> ${kept}")
    endif()
  endforeach()
endfunction()

cmake_language(DEFER CALL active_recognition_use_this_python)
