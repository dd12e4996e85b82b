// Reads a LAS file with copc.js (Hobu's LAS 1.4 reader, npm package copc) and prints, as JSON,
// its header, its VLRs (the WKT of LASF_Projection 2112 as text) and every point's fields:
// X Y Z (scaled, m), Intensity, ReturnNumber, NumberOfReturns, UserData, GpsTime.
// Usage: node read_las.js FILE.las
'use strict';
const fs = require('fs');
const { Las } = require('copc');

async function main() {
  const bytes = new Uint8Array(fs.readFileSync(process.argv[2]));
  const get = async (begin, end) => bytes.subarray(begin, end);
  const header = Las.Header.parse(bytes.subarray(0, 375));
  const vlrs = await Las.Vlr.walk(get, header);
  const wkt = Las.Vlr.find(vlrs, 'LASF_Projection', 2112);
  const points = bytes.subarray(header.pointDataOffset, header.pointDataOffset + header.pointCount * header.pointDataRecordLength);
  const view = Las.View.create(points, header);
  const names = ['X', 'Y', 'Z', 'Intensity', 'ReturnNumber', 'NumberOfReturns', 'UserData', 'GpsTime'];
  const getters = names.map((n) => view.getter(n));
  const rows = [];
  for (let i = 0; i < view.pointCount; ++i) rows.push(getters.map((g) => g(i)));
  const text = wkt ? Buffer.from(bytes.subarray(wkt.contentOffset, wkt.contentOffset + wkt.contentLength)).toString('latin1') : null;
  process.stdout.write(JSON.stringify({ header, vlrs, wkt: text && text.replace(/\0+$/, ''), fields: names, points: rows }));
}

main().catch((e) => {
  process.stderr.write(String(e && e.stack ? e.stack : e) + '\n');
  process.exit(1);
});
