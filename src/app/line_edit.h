/* The interactive session's line editing with readline (line_edit.c):
 * tab completion that walks the Lua value before the cursor, and the
 * history file. Part of the executable (main.c runs the session). */
#ifndef SX_LINE_EDIT_H
#define SX_LINE_EDIT_H

#ifdef SX_HAVE_READLINE
#include <lua.h>

void sx__edit_start(lua_State *L);         /* completion in L's globals; the history file read */
void sx__edit_remember(const char *entry); /* a statement entered, into the history and its file */
void sx__edit_end(void);                   /* the history file cut to its last entries; completion's memory freed */
#endif

#endif
