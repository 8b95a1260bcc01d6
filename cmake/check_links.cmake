# The one-way rule of the layout (docs/layout.md "Layout"), checked when the build is
# configured: every library and program of ours may link, directly or through another of
# ours, only the libraries listed for it here. In particular the server and the client
# never link each other or the lab, the live view (cohaptic_view, which both the server and
# the lab's replay use) links neither, and common links nothing of ours. A lab tool that needs
# the server or the client starts it as a process instead.
# Reads LINK_LIBRARIES and INTERFACE_LINK_LIBRARIES (static libraries list their private
# links there as $<LINK_ONLY:...>); a violation stops the configuration with the chain of
# links that broke the rule.

set(COHAPTIC_OUR_LIBRARIES cohaptic_common cohaptic_proto cohaptic_net cohaptic_view cohaptic_server cohaptic_client
  cohaptic_lab)

set(COHAPTIC_MAY_LINK_cohaptic_common "")
set(COHAPTIC_MAY_LINK_cohaptic_proto cohaptic_common)
set(COHAPTIC_MAY_LINK_cohaptic_net cohaptic_proto cohaptic_common)
set(COHAPTIC_MAY_LINK_cohaptic_view cohaptic_net cohaptic_proto cohaptic_common)
set(COHAPTIC_MAY_LINK_cohaptic_server cohaptic_view cohaptic_net cohaptic_proto cohaptic_common)
set(COHAPTIC_MAY_LINK_cohaptic_client cohaptic_net cohaptic_proto cohaptic_common)
set(COHAPTIC_MAY_LINK_cohaptic_lab cohaptic_view cohaptic_net cohaptic_proto cohaptic_common)
set(COHAPTIC_MAY_LINK_cohaptic-server cohaptic_server ${COHAPTIC_MAY_LINK_cohaptic_server})
set(COHAPTIC_MAY_LINK_cohaptic-client cohaptic_client ${COHAPTIC_MAY_LINK_cohaptic_client})
set(COHAPTIC_MAY_LINK_cohaptic-lab cohaptic_lab ${COHAPTIC_MAY_LINK_cohaptic_lab})

# The libraries of ours that `target` links directly, publicly or privately.
function(cohaptic_our_direct_links target result)
  get_target_property(private_links ${target} LINK_LIBRARIES)
  get_target_property(interface_links ${target} INTERFACE_LINK_LIBRARIES)
  set(ours "")
  foreach(link IN LISTS private_links interface_links)
    string(REGEX REPLACE "^\\$<LINK_ONLY:(.+)>$" "\\1" link "${link}")
    if(link IN_LIST COHAPTIC_OUR_LIBRARIES)
      list(APPEND ours ${link})
    endif()
  endforeach()
  list(REMOVE_DUPLICATES ours)
  set(${result} ${ours} PARENT_SCOPE)
endfunction()

# Walks everything of ours that `target` links, breadth first, and stops the configuration
# at the first library it may not link, naming the chain that reaches it.
function(cohaptic_check_links target)
  set(allowed ${COHAPTIC_MAY_LINK_${target}})
  set(queue ${target})
  set(seen ${target})
  set(chain_${target} ${target})
  while(queue)
    list(POP_FRONT queue current)
    cohaptic_our_direct_links(${current} links)
    foreach(link IN LISTS links)
      if(link IN_LIST seen)
        continue()
      endif()
      list(APPEND seen ${link})
      set(chain_${link} "${chain_${current}} -> ${link}")
      if(NOT link IN_LIST allowed)
        if(allowed)
          string(REPLACE ";" ", " allowed_text "${allowed}")
          set(allowed_text "only ${allowed_text}")
        else()
          set(allowed_text "nothing of ours")
        endif()
        message(FATAL_ERROR "cohaptic link check: ${target} links ${link} (${chain_${link}}), but it may link "
                            "${allowed_text}. The server and the client never link each other or the lab, the view "
                            "links no program's library, and "
                            "common links nothing of ours (README.md, \"Layout\"; cmake/check_links.cmake).")
      endif()
      list(APPEND queue ${link})
    endforeach()
  endwhile()
endfunction()

foreach(target IN LISTS COHAPTIC_OUR_LIBRARIES ITEMS cohaptic-server cohaptic-client cohaptic-lab)
  if(TARGET ${target})
    cohaptic_check_links(${target})
  endif()
endforeach()
