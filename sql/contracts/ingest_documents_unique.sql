-- every document id names exactly one document
select doc_id, count(*) as n
from documents
group by doc_id
having count(*) > 1
