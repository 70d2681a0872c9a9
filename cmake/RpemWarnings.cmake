# rpem_target_defaults(<target>): project-wide warnings, optional -Werror and sanitizers.
function(rpem_target_defaults target)
  target_compile_options(${target} PRIVATE
    -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
    -Wnon-virtual-dtor -Wold-style-cast -Wcast-align -Wunused -Woverloaded-virtual
    -Wno-restrict  # GCC 12 at -O3 reports false positives inside std::string (GCC bug 105329)
    -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough)
  # No code reads errno after a math call; without it sqrt and friends compile to single instructions.
  target_compile_options(${target} PRIVATE -fno-math-errno)
  if(RPEM_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(RPEM_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=${RPEM_SANITIZE} -fno-omit-frame-pointer)
    target_link_options(${target} PRIVATE -fsanitize=${RPEM_SANITIZE})
  endif()
endfunction()
