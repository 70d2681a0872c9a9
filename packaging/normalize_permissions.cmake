# CPACK_PRE_BUILD_SCRIPTS hook: runs on cpack's staging tree before it is packed. Directories that the
# install created implicitly inherit the builder's umask (mkdir is masked; CMake does not chmod them), so
# a builder with umask 077 would ship a 0700 /etc/rpemd that locks the service's unprivileged user out of
# its configuration. Every directory in the package is 0755, whatever the umask.
file(GLOB_RECURSE entries LIST_DIRECTORIES true "${CPACK_TEMPORARY_DIRECTORY}/*")
foreach(entry IN LISTS entries)
  if(IS_DIRECTORY "${entry}" AND NOT IS_SYMLINK "${entry}")
    file(CHMOD "${entry}" PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE
                                       WORLD_READ WORLD_EXECUTE)
  endif()
endforeach()
