-- seixo.plot: live plots of a model's histories through gnuplot, redrawn
-- while the model cycles (YADE's plot.plot(), PFC's history plots):
--   local plot = require "seixo.plot"
--   m:history("ke", "kinetic", {every = 100})
--   local p = plot.live(m, {"ke"}, {every = 1000})   -- a window that follows the run
--   m:solve{ratio = 1e-4}
--   p:close()
--
-- One gnuplot process per plot, fed through a pipe: each refresh sends the
-- samples as inline data ('-'), so nothing is written to disk. The refresh
-- is a callback of the model (m:on "after"), so it runs between steps and
-- never changes the run: the same bits with or without a plot.

local plot = {}
local seixo = require "seixo"  -- a global in the executable, not under a stock lua5.4

local function fail(fmt, ...) error(string.format(fmt, ...), 3) end

local keys = {every = true, terminal = true, output = true, title = true, x = true, log = true}

-- The gnuplot commands of one refresh: a plot of each history against x.
local function commands(m, names, opts)
  local out = {}
  local parts = {}
  for i, name in ipairs(names) do
    parts[i] = string.format("'-' using 1:2 with lines title '%s'", name:gsub("'", "''"))
  end
  if opts.output then out[#out + 1] = string.format("set output '%s'", opts.output:gsub("'", "''")) end
  out[#out + 1] = "plot " .. table.concat(parts, ", ")
  for _, name in ipairs(names) do
    local h = m:history(name)
    local xs = opts.x == "time" and h.times or h.steps
    for k = 1, #h.values do out[#out + 1] = string.format("%.17g %.17g", xs[k], h.values[k]) end
    out[#out + 1] = "e"
  end
  return table.concat(out, "\n") .. "\n"
end

local Plot = {}
Plot.__index = Plot

--- Redraws the plot now.
function Plot:draw()
  if not self.pipe then error("plot: the plot has been closed", 2) end
  self.pipe:write(commands(self.model, self.names, self.opts))
  self.pipe:flush()
  self.draws = self.draws + 1
end

--- Stops refreshing, closes gnuplot (its window closes with it).
function Plot:close()
  if not self.pipe then return end
  self.model:off(self.callback)
  self.pipe:close()
  self.pipe = nil
end

Plot.__close = Plot.close
Plot.__gc = Plot.close

function Plot:__tostring()
  return string.format("seixo.plot of %s (%d draws%s)", table.concat(self.names, ", "), self.draws,
                       self.pipe and "" or ", closed")
end

--- A live plot of histories of m (their names) redrawn every `every` steps
--- (default 1000) while m cycles, and at once. opts: terminal (gnuplot's,
--- e.g. "qt", "x11", "dumb", "pngcairo"; default gnuplot's own), output (a
--- file for a file terminal, rewritten at each refresh), title, x = "step"
--- (default) or "time", log = true for a logarithmic y axis.
function plot.live(m, names, opts)
  -- a model answers m:histories(); another userdata (a file handle) may index to nil
  local hok, histories = pcall(function() return m:histories() end)
  if type(m) ~= "userdata" or not hok or type(histories) ~= "table" then
    fail("plot.live: a model expected, got %s", io.type(m) or type(m))
  end
  opts = opts or {}
  if type(opts) ~= "table" then fail("plot.live: an options table expected, got %s", type(opts)) end
  for _, k in ipairs({"terminal", "output", "title"}) do
    if opts[k] ~= nil and type(opts[k]) ~= "string" then
      fail("plot.live: %s must be a string (got %s)", k, type(opts[k]))
    end
  end
  if type(names) == "string" then names = {names} end
  if type(names) ~= "table" or #names == 0 then fail("plot.live: names of histories expected") end
  for k in pairs(opts) do
    if not keys[k] then fail("plot.live: unknown key '%s' (valid keys: every, log, output, terminal, title, x)", tostring(k)) end
  end
  local have = {}
  for _, name in ipairs(histories) do have[name] = true end
  for _, name in ipairs(names) do
    if not have[name] then fail("plot.live: no history named '%s' (add it with m:history)", tostring(name)) end
  end
  if opts.x ~= nil and opts.x ~= "step" and opts.x ~= "time" then fail("plot.live: x must be 'step' or 'time'") end
  -- a file terminal without a file writes its image to the standard output
  local file_terminals = {png = true, pngcairo = true, pdfcairo = true, svg = true, postscript = true, eps = true,
                          epscairo = true, jpeg = true, gif = true, cairolatex = true, pdf = true}
  local term = opts.terminal and opts.terminal:match("^%s*(%S+)")
  if term and file_terminals[term] and not opts.output then
    fail("plot.live: terminal '%s' writes a file: give output = 'name' (else the image goes to the standard output)", term)
  end
  local every = opts.every or 1000
  if type(every) ~= "number" or every ~= math.floor(every) or every < 1 or every == math.huge then
    fail("plot.live: every must be a whole number of steps >= 1")
  end
  -- under mpirun every rank runs the script: rank 0 alone draws (the others
  -- would open a window each, or print a dumb terminal's plot again, or
  -- write the same file at once); the others keep the callback, since every
  -- rank must cut its cycles at the same steps, and feed nothing
  local pipe = seixo.rank() == 0 and io.popen("gnuplot 2>/dev/null", "w") or io.open("/dev/null", "w")
  if not pipe then fail("plot.live: gnuplot cannot be run (apt-get install gnuplot-qt, or gnuplot-nox with terminal = 'dumb')") end
  local head = {}
  if opts.terminal then head[#head + 1] = "set terminal " .. opts.terminal end
  head[#head + 1] = string.format("set title '%s'", (opts.title or table.concat(names, ", ")):gsub("'", "''"))
  head[#head + 1] = "set xlabel '" .. (opts.x == "time" and "time (s)" or "step") .. "'"
  head[#head + 1] = "set grid"
  if opts.log then head[#head + 1] = "set logscale y" end
  pipe:write(table.concat(head, "\n") .. "\n")
  local p = setmetatable({model = m, names = names, opts = opts, pipe = pipe, draws = 0}, Plot)
  p.callback = m:on("after", function() p:draw() end, {every = math.tointeger(every)})
  p:draw()
  return p
end

return plot
