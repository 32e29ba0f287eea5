-- seixo.lab.csv: the lab's records as CSV files (lab.write_csv).
local pool = require "seixo.pool"
local csv = {}

-- Files written whole or not at all (a temporary name, renamed when complete)
local write_file = pool.write_file

-- A header name as a CSV field: quoted when it holds a comma, a quote or a
-- line break (RFC 4180, as m:history_csv quotes; unquoted, "a,b" made two
-- columns of one).
local function field(name)
  name = tostring(name)
  if not name:find('[,"\r\n]') then return name end
  return '"' .. name:gsub('"', '""') .. '"'
end

-- A number as a cell: %.10g, and NaN and the infinities as nan, inf, -inf
-- on every platform (the C library wrote -nan).
local function cell(x)
  if x ~= x then return "nan" end
  if x == math.huge then return "inf" end
  if x == -math.huge then return "-inf" end
  return string.format("%.10g", x)
end

--- Writes rows (arrays of numbers; nil: an empty cell) under a header to a
--- CSV file, atomically. A row longer than the header, or a cell that is
--- not a number, is an error naming it (they were cut, or failed in
--- string.format, silently or unnamed).
function csv.write(path, header, rows)
  if type(header) ~= "table" then error("lab.write_csv: header: a table of names expected, got " .. type(header), 2) end
  if type(rows) ~= "table" then error("lab.write_csv: rows: a table of rows expected, got " .. type(rows), 2) end
  local names = {}
  for k = 1, #header do names[k] = field(header[k]) end
  local out = {table.concat(names, ",")}
  for i, row in ipairs(rows) do
    if type(row) ~= "table" then error(string.format("lab.write_csv: row %d: a table expected, got %s", i, type(row)), 2) end
    if #row > #header then
      error(string.format("lab.write_csv: row %d has %d cells, the header %d names", i, #row, #header), 2)
    end
    local cells = {}
    for k = 1, #header do
      local x = row[k]
      if x ~= nil and type(x) ~= "number" then
        error(string.format("lab.write_csv: row %d, column '%s': a number expected, got %s", i, tostring(header[k]),
                            type(x)), 2)
      end
      cells[k] = x == nil and "" or cell(x)
    end
    out[#out + 1] = table.concat(cells, ",")
  end
  write_file(path, table.concat(out, "\n") .. "\n")
end

return csv
