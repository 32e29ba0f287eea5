-- seixo.lab.polling: while rank 0 runs work of its own and hands out the
-- rest over the MPI ranks (pool.hand_out), each model a lab test or a
-- genesis opens calls poll() every POLL_STEPS steps (a callback: no bit
-- changes), so that rank 0 hands out work to the ranks that end meanwhile.

local polling = {}

local on_model_open
local POLL_STEPS = 500

--- fn(...), with poll() called every POLL_STEPS steps of each model opened
--- meanwhile (polling.opened).
function polling.run(poll, fn, ...)
  local was = on_model_open
  local _ <close> = setmetatable({}, {__close = function() on_model_open = was end})
  on_model_open = function(m) m:on("after", poll, {every = POLL_STEPS}) end
  return fn(...)
end

--- To call with each model a lab test or a genesis opens.
function polling.opened(m)
  if on_model_open then on_model_open(m) end
end

return polling
