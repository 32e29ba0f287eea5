-- seixo.lab.csv: the lab's records as CSV files (lab.write_csv).
local pool = require "seixo.pool"
local csv = {}

-- Files written whole or not at all (a temporary name, renamed when complete)
local write_file = pool.write_file

--- Writes rows (arrays of numbers) under a header to a CSV file, atomically.
function csv.write(path, header, rows)
  local out = {table.concat(header, ",")}
  for _, row in ipairs(rows) do
    local cells = {}
    for k = 1, #header do cells[k] = row[k] == nil and "" or string.format("%.10g", row[k]) end
    out[#out + 1] = table.concat(cells, ",")
  end
  write_file(path, table.concat(out, "\n") .. "\n")
end

return csv
